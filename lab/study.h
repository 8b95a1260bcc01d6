// `cohaptic-lab study FILE --out DIR`: a lab study with simulated participants.
//
// The study file (YAML, docs/studies.md "Study files") names a scene, the participants (each a
// scripted or hand-model device following a trajectory), the factors (shift_ms,
// step_nodes, sim_rate_hz, protocol, jitter_ms, loss; every combination is a condition),
// the repetitions and the order (random with a seed, a balanced Latin square, or
// sequential). Every trial runs a real cohaptic-server and one cohaptic-client per
// participant on loopback, each recording (MCAP) under DIR/trials/NNN/. After each trial
// the measures (common/study/measures.h) of every participant's forces go into
// DIR/trials.csv; at the end DIR/summary.csv (mean, sd, n per condition and measure) and
// the figures: DIR/figures/fig4.svg (normalised force against time under step delay, P0
// and P1, the paper's Fig. 4) and DIR/figures/<measure>.svg (each measure per condition).
// Interrupted and run again with the same study file and DIR, it continues where it
// stopped: trials already in trials.csv are not run again. A study with a
// `paired_comparison` block then has its pairs rated and analysed by Scheffe's method
// (lab/paired_comparison_study.h).
#pragma once

#include <filesystem>
#include <map>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "lab/lab_command.h"
#include "lab/paired_comparison_study.h"

namespace cohaptic {

struct StudyParticipant {
  std::string name;
  std::string device;  ///< "script" or "hand"
  std::filesystem::path trajectory;
  int slot = 0;  ///< the scene tool it holds (its position in the list)
};

/// One combination of factor levels.
struct StudyCondition {
  double shift_ms = 0, jitter_ms = 0, loss = 0, sim_rate_hz = 0;
  int step_nodes = 0;
  std::string protocol = "P1";
  std::string name() const;  ///< e.g. "S30-T150-P1" (+ "-J5", "-L0.1", "-R40" when set)
};

struct StudyTrial {
  int index = 0;  ///< 1-based, in run order
  int repetition = 1;
  StudyCondition condition;
};

struct Study {
  std::filesystem::path file;
  std::string name;
  std::filesystem::path scene;
  double trial_duration_s = 12;
  std::string condensation = "naive";  ///< how the server builds M~: naive shows the step delay
  std::vector<StudyParticipant> participants;
  std::vector<StudyCondition> conditions;
  int repetitions = 1;
  std::string order = "random";  ///< random | latin_square | sequential
  unsigned seed = 1;
  std::map<std::string, std::string> session;  ///< participant/session fields, copied to every row
  std::vector<StudyTrial> trials;              ///< in run order
  /// A paired-comparison study: its trials measure every condition `repetitions` times, then
  /// its subjects rate every pair (lab/paired_comparison_study.h).
  std::optional<PairedComparisonDesign> paired;
};

/// Parses and validates a study file (errors name the file, line and key). Trials are
/// generated in the file's order.
Study load_study(const std::filesystem::path& file);

/// Parses study text; `file` names it in messages and resolves the relative paths in it.
Study parse_study(const std::string& yaml_text, const std::filesystem::path& file);

struct StudyRunOptions {
  std::filesystem::path out;
  std::string server_program;  ///< empty: cohaptic-server beside this program's build
  std::string client_program;  ///< empty: cohaptic-client beside this program's build
  // A study rated by people (lab/person_pairs.h) runs one subject at a time:
  int subject = 0;     ///< 1-based
  std::string device;  ///< that subject's cohaptic-client --device
  std::string
      rating_page;  ///< HOST:PORT: commands from a rating page served there, not the terminal
  std::istream* input = nullptr;   ///< the subject's commands; null: standard input
  std::ostream* output = nullptr;  ///< what the subject reads; null: standard output
};

/// Runs the trials not yet in out/trials.csv (and those that failed), then writes the
/// summary and the figures. Returns the exit code: 0, or 1 if a trial failed. A study rated
/// by people runs options.subject's unrated pairs instead, and the analysis once every
/// subject has rated every pair.
int run_study(const std::filesystem::path& file, const StudyRunOptions& options);

/// `cohaptic-lab study FILE --out DIR [--server-program P] [--client-program P]`.
LabCommand add_study_command(CLI::App& lab);

}  // namespace cohaptic
