// Every program's log goes to stderr, so that stdout carries only what was asked for (a
// table, JSON, CSV) and a script can read it whatever the log level.
#pragma once

namespace cohaptic {

/// Makes spdlog's default logger write to stderr, with the programs' line pattern
/// ("[12:34:56.789] [info] ..."). Call first thing in main, before anything logs.
void log_to_stderr();

}  // namespace cohaptic
