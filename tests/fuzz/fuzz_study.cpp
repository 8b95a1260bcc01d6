// Fuzz target: the study file loader (lab/study.h), on the text of a study file that sits
// in the repository's scenes/studies/ directory (so its scene and trajectories resolve to
// real files, and the scene it names is loaded too).
//
// Input: the YAML text. Properties:
//   - parse_study() either returns a study or throws cohaptic::Error naming the file: no
//     exception of the YAML library, or anything else, escapes;
//   - a study accepted has participants, conditions, and as many trials as conditions times
//     repetitions, each of a repetition in range.
#include <cstdint>
#include <string>

#include "common/util/error.h"
#include "lab/study.h"
#include "tests/fuzz/fuzz_support.h"

using namespace cohaptic;
using fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path file =
      std::filesystem::path(COHAPTIC_SOURCE_DIR) / "scenes" / "studies" / "fuzzed.yaml";
  try {
    const Study study = parse_study(std::string(reinterpret_cast<const char*>(data), size), file);
    require(!study.participants.empty(), "a study has participants");
    require(!study.conditions.empty(), "a study has conditions");
    require(study.trials.size() ==
                study.conditions.size() * static_cast<std::size_t>(study.repetitions),
            "every condition runs once per repetition");
    for (const StudyTrial& trial : study.trials)
      require(trial.repetition >= 1 && trial.repetition <= study.repetitions,
              "a trial's repetition is in range");
  } catch (const Error&) {
  }
  return 0;
}
