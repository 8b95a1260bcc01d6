// A scene's simulation can be copied, and the copy steps bit for bit like the original and
// apart from it: every shipped scene with two surgeons' scripts (scenes/<scene>/surgeon_a.yaml
// and surgeon_b.yaml), its surgeons pressing as scripted, is copied at a few points of its
// presses; the original runs on to the end and is destroyed, then each copy runs from where
// it was taken, given the same tool positions and buttons at the same times. Every step's report
// and pressing users, every IR built (its wire bytes), every P0 force and, every tenth step, every
// linear elastic body's state solve (the live view's), must have the same bits in both. Running the
// original first means a state the two shared (a pointer copied instead of what it points to) would
// be advanced twice, and the copy would part from it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "common/haptics/trajectory.h"
#include "common/model/scene_compliance.h"
#include "common/scene/load_scene.h"
#include "common/sim/elastic_states.h"
#include "common/sim/ir_build_options.h"
#include "common/sim/scene_simulation.h"
#include "proto/wire/ir_convert.h"
#include "support/shipped_scenes.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

namespace fs = std::filesystem;

// The simulation's clock advances this much per step, the surgeons' scripts kScriptPerStep:
// a press reached in a few hundred steps, the dynamic bodies at a step a server makes.
constexpr double kStepSeconds = 0.002;
constexpr double kScriptPerStep = 0.01;
constexpr int kMostStepsBeforeAPress = 1000;
constexpr int kStepsPerCondition = 45;
constexpr int kStepDelayNodes = 8;
constexpr int kCopies = 4;
constexpr int kStepsBetweenCopies = 60;

// The scene's file: its coarse variant where one is shipped beside it (scenes/<scene>_coarse.yaml:
// the same contact model, scripts and presses on a mesh whose compliance is ready in seconds,
// not minutes).
std::string scene_file(const std::string& scene) {
  const std::string coarse = testing::source_path("scenes/" + scene + "_coarse.yaml");
  return fs::exists(coarse) ? coarse : testing::source_path("scenes/" + scene + ".yaml");
}

// A value's bytes (a vector's: its entries'), so that two runs compare bit for bit (NaN and
// -0 included).
template <typename T>
void append_bits(std::string& out, const T& value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

void append_vector_bits(std::string& out, const Eigen::Ref<const Eigen::VectorXd>& values) {
  for (Eigen::Index i = 0; i < values.size(); ++i) append_bits(out, values[i]);
}

// One session of scripted surgeons over a scene's simulation, step by step.
class ScriptedSession {
 public:
  explicit ScriptedSession(const std::string& scene)
      : scene_(load_scene(scene_file(scene))),
        model_(build_model(scene_)),
        compliance_(prepare_scene_compliance(model_, true, std::nullopt)) {
    for (const char* surgeon : {"surgeon_a.yaml", "surgeon_b.yaml"})
      scripts_.push_back(load_trajectory(testing::source_path("scenes/" + scene + "/" + surgeon)));
  }

  SceneSimulation make_simulation() const {
    SimulationOptions options;
    options.ir = ir_build_options(scene_.haptic);
    return SceneSimulation(model_, compliance_.per_body, scene_.tools, options);
  }

  // Steps [first, last) of `simulation`: what each gives, as bytes; counts in `pressing` the
  // steps at which some user pressed.
  std::vector<std::string> run(SceneSimulation& simulation, int first, int last,
                               int* pressing = nullptr) const {
    std::vector<std::string> steps;
    for (int i = first; i < last; ++i) {
      // The step delay switched on and off, as a study's conditions switch it: the held
      // set B changes, and the IRs are condensed again over it.
      if (i % kStepsPerCondition == 0)
        simulation.set_step_delay_nodes(i / kStepsPerCondition % 2 ? kStepDelayNodes : 0);
      for (int user = 0; user < simulation.user_count(); ++user) {
        const Trajectory& script = scripts_[static_cast<std::size_t>(user) % scripts_.size()];
        const double t = i * kScriptPerStep;
        simulation.set_tool(user, script.position(t), script.buttons(t));
      }
      std::string out;
      const StepReport report = simulation.step(i * kStepSeconds);
      append_bits(out, report.rebuilt);
      append_bits(out, report.recomputed);
      append_bits(out, report.ir_bytes);
      append_bits(out, report.boundary_nodes);
      append_bits(out, report.obstacle_nodes);
      append_bits(out, report.sphere_nodes_outside_patches);
      bool any_pressing = false;
      for (int user = 0; user < simulation.user_count(); ++user) {
        any_pressing = any_pressing || simulation.pressing(user);
        append_bits(out, simulation.pressing(user));
        append_bits(out, simulation.body_of(user));
        if (simulation.ir_changed(user) && simulation.ir(user))
          out += wire::to_wire(simulation.ir(user)->ir).SerializeAsString();
        const ForceSample sample = simulation.force(user);
        append_vector_bits(out, sample.force);
        append_bits(out, sample.triangle);
        append_bits(out, sample.depth);
        append_bits(out, sample.flags);
      }
      if (i % 10 == 0)
        for (const std::optional<StateSolution>& state : solve_elastic_states(simulation))
          if (state) {
            append_vector_bits(out, state->contact_forces);
            append_vector_bits(out, state->boundary_forces);
            for (const Eigen::Vector3d& force : state->tool_forces) append_vector_bits(out, force);
          }
      if (pressing && any_pressing) ++*pressing;
      steps.push_back(std::move(out));
    }
    return steps;
  }

 private:
  Scene scene_;
  Model model_;
  SceneCompliance compliance_;
  std::vector<Trajectory> scripts_;
};

class SimulationCopy : public ::testing::TestWithParam<std::string> {};

TEST_P(SimulationCopy, StepsBitForBitLikeTheOriginalAndApartFromIt) {
  const ScriptedSession session(GetParam());
  std::optional<SceneSimulation> original(session.make_simulation());
  int first = 0;  // the first step after the first press
  for (int pressing = 0; pressing == 0 && first < kMostStepsBeforeAPress; ++first)
    session.run(*original, first, first + 1, &pressing);
  ASSERT_LT(first, kMostStepsBeforeAPress) << "no surgeon pressed";
  // Copies taken as the presses go on (contact state, held sets, supports and caches in use),
  // the original run to the end through them all.
  const int end = first + kCopies * kStepsBetweenCopies;
  std::vector<std::pair<int, SceneSimulation>> copies;
  std::vector<std::string> original_steps;
  int pressing = 0;
  for (int step = first; step < end; step += kStepsBetweenCopies) {
    std::vector<std::string> steps =
        session.run(*original, step, step + kStepsBetweenCopies, &pressing);
    original_steps.insert(original_steps.end(), steps.begin(), steps.end());
    copies.emplace_back(step + kStepsBetweenCopies, *original);
  }
  EXPECT_GT(pressing, 0);
  copies.pop_back();  // taken at the end: nothing to compare
  // Gone before the copies step: a copy that still reads the original's memory reads freed
  // memory (AddressSanitizer's test run stops there).
  original.reset();
  for (auto& [taken, copy] : copies) {
    const std::vector<std::string> copy_steps = session.run(copy, taken, end);
    for (std::size_t i = 0; i < copy_steps.size(); ++i)
      ASSERT_EQ(original_steps[static_cast<std::size_t>(taken - first) + i], copy_steps[i])
          << "the copy taken at step " << taken << " parted from the original at step "
          << taken + static_cast<int>(i);
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, SimulationCopy,
                         ::testing::ValuesIn(testing::scenes_with_surgeons()),
                         [](const ::testing::TestParamInfo<std::string>& scene) {
                           return testing::scene_test_name(scene.param);
                         });

}  // namespace
}  // namespace cohaptic
