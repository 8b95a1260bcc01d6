// LabCommand: one subcommand of cohaptic-lab, as its tool adds it to the command line.
//
// Each lab tool has `LabCommand add_<tool>_command(CLI::App& lab)` beside its run_<tool>():
// it declares the subcommand and its options (owned by the returned `run`), and `run`
// turns the parsed options into the tool's call and returns the process's exit code.
// lab/main.cpp only lists the tools; it knows none of their options. Exit codes: 0 done,
// 1 the tool failed (or found a difference), 2 bad command-line input; tools may add their
// own (summarize: 3 unhealthy).
#pragma once

#include <functional>

namespace CLI {
class App;
}

namespace cohaptic {

struct LabCommand {
  CLI::App* subcommand = nullptr;  ///< owned by the app it was added to
  std::function<int()> run;        ///< call after parsing, when subcommand->parsed()
};

}  // namespace cohaptic
