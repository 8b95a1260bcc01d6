// A person's session of a paired-comparison study (`rater: {kind: person}`):
//   cohaptic-lab study FILE --out DIR --subject N --device SPEC
// For subject N (1-based) it serves each pair of the subject's plan not yet rated, one pair
// at a time, in one cohaptic-server holding both conditions (`--condition first:...
// --condition second:...`, `--control`), with one cohaptic-client on the subject's device.
// The subject feels the first condition, switches between the two as often as wanted, and
// rates the pair on the study's scale; nothing on the terminal says which condition is which,
// only "first" and "second". First come the practice pairs (felt, not rated; the object
// shown unless show_object is never). With switch_button the device's button switches too
// (cohaptic-server --switch-button). Each switch, however made, goes to the pair's server
// recording and report (DIR/pairs/sNN-pMM/) and, when the pair ends, from the report to
// DIR/switches.csv (subject, pair, time_s in the server's session, serving); each rating to
// DIR/ratings.csv when confirmed, so an interrupted session (q, or the input ending)
// continues at the next unrated pair when run again.
//
// The subject's commands come from the terminal, or with a rating page (lab/rating_page.h)
// from the page only, the terminal then logging them. The terminal, one command a line (so a
// scripted input drives it as a person would):
//   s                 switch to the other condition
//   +2 ... -2 (or 2)  choose a grade; an empty line or y confirms it, another grade replaces it
//   n                 (practice) go on to the next pair
//   q                 stop; run the same command again to continue
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "lab/paired_comparison_study.h"

namespace cohaptic {

class RatingPage;

struct PersonSessionSetup {
  std::string study_name;
  std::filesystem::path scene;
  std::string condensation;                  ///< the server's --condensation
  std::vector<std::string> condition_names;  ///< the study's
  /// Per condition, the settings of a --condition (after "NAME:"), e.g.
  /// "protocol=P0,step_nodes=150".
  std::vector<std::string> condition_settings;
  PairedComparisonDesign design;
  std::filesystem::path out;
  std::string server_program, client_program;
  int subject = 0;     ///< 1-based
  std::string device;  ///< the client's --device for this subject
};

/// Runs the subject's unrated pairs, taking commands from `page` when given, else from `in`.
/// Returns true when the subject has rated every pair, false when stopped first. Throws Error
/// when a program cannot start.
bool run_person_pairs(const PersonSessionSetup& setup, std::istream& in, std::ostream& out,
                      RatingPage* page = nullptr);

}  // namespace cohaptic
