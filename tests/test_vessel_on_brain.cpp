// The clinical scene of the several-objects interaction (scenes/objects/vessel_on_brain.yaml):
// a vein lying across the vertex of the brain, its ends anchored. A surgeon pressing the vein
// must feel the brain through it: with the same press, the force rises with the brain's
// stiffness (E_B 2 kPa against 4 kPa), and without the brain behind it (the scene without
// its interaction: the vein held only at its ends) the force is lower still.
#include <gtest/gtest.h>

#include <string>

#include "common/model/scene_compliance.h"
#include "common/scene/load_scene.h"
#include "common/sim/scene_simulation.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

// The mean upward force on a sphere pressed 1.6 mm into the vein's top left of the midline,
// over the last 0.1 s of a 0.3 s hold [N]; the vein first settles on the brain for 0.3 s.
double vein_press_force(double brain_youngs_modulus, bool with_brain) {
  Scene scene = load_scene(testing::source_path("scenes/objects/vessel_on_brain.yaml"));
  std::get<ElasticObjectSpec>(scene.objects.at(1).body).material.youngs_modulus =
      brain_youngs_modulus;
  if (!with_brain) scene.interactions.clear();
  const Model model = build_model(scene);
  const SceneCompliance compliance = prepare_scene_compliance(model, true, std::nullopt);
  SceneSimulation simulation(model, compliance.per_body, model.scene.tools, SimulationOptions{});
  const auto& vein = std::get<MassSpringSimulation>(simulation.body(0));
  const Eigen::Vector3d above(-0.006, -0.010, 0.0766);  // the sphere just touches the vein at rest
  const Eigen::Vector3d far(0.0, 0.0, 0.2);
  double time = 0, sum = 0;
  int samples = 0;
  for (int i = 0; i < 900; ++i, time += 0.001) {
    const double pressed =
        i < 300 ? -1 : std::min((i - 300) / 300.0, 1.0);  // lowered 1.6 mm over 0.3 s
    simulation.set_tool(
        0, pressed < 0 ? far : Eigen::Vector3d(above - Eigen::Vector3d(0, 0, 0.0016 * pressed)));
    simulation.set_tool(1, far);
    simulation.step(time);
    EXPECT_TRUE(vein.state().positions.allFinite());
    if (i >= 800) {
      EXPECT_EQ(simulation.body_of(0), 0);
      sum += vein.reaction(0).force.z();
      ++samples;
    }
  }
  return sum / samples;
}

TEST(VesselOnBrain, SurgeonFeelsTheBrainThroughTheVein) {
  const double soft = vein_press_force(2000, true);
  const double stiff = vein_press_force(4000, true);
  const double alone = vein_press_force(2000, false);
  RecordProperty("force_brain_2kpa_n", std::to_string(soft));
  RecordProperty("force_brain_4kpa_n", std::to_string(stiff));
  RecordProperty("force_vein_alone_n", std::to_string(alone));
  EXPECT_GT(alone, 0);
  // Measured: 0.052 N alone, 0.063 N on the 2 kPa brain, 0.070 N on the 4 kPa one (the
  // tool's depth is fixed, so the vein bends more over the stiffer brain: not twice). A
  // lumped backing gives 0.097 and 0.108 N: its per-node springs sum B's stiffness over
  // every backed node, exact only when all of them sink together, which overstates the
  // brain under a local press.
  EXPECT_GT(soft, 1.15 * alone) << "the brain adds to what the vein's ends hold";
  EXPECT_GT(stiff, 1.05 * soft) << "a stiffer brain pushes back harder through the vein";
}

}  // namespace
}  // namespace cohaptic
