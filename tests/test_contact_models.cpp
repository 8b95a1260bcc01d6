// The two contact models side by side as the cube's mesh is refined.
//
// What theory says, and the test checks: a point on an elastic half-space has no finite
// stiffness, so for a fixed depth both models' forces fall like the element size h (force
// x divisions stays nearly constant); and node translation constrains the whole triangle
// where the point model constrains only the contact point, so by minimum energy the force
// it transmits to the object is at least the point model's. The paper's reported reaction
// under node translation, sum w_i f_i, is an average of the nodal forces, about a third
// of what the triangle transmits. The table shows all three.
#include <gtest/gtest.h>

#include <random>

#include "common/model/static_contact.h"
#include "common/scene/load_scene.h"
#include "support/cube_scene.h"

namespace cohaptic {
namespace {

TEST(ContactModels, ForcesFallWithTheElementSizeAndTranslationTransmitsAtLeastThePointModel) {
  std::printf(
      "  divisions  h (mm)  paper's reaction  transmitted (translation)  point   point/transmitted "
      " "
      "(mean |F_z| over 6 presses 1 mm deep, N)\n");
  std::vector<double> scaled_translation, scaled_point;
  for (int divisions : {6, 11, 16}) {
    testing::CubeSceneOptions scene;
    scene.divisions = divisions;
    const Model model = build_model(parse_scene(testing::cube_scene_yaml(scene), "cube.yaml"));
    const ElasticBody& body = single_elastic_body(model);
    std::mt19937 rng(static_cast<unsigned>(divisions));
    std::uniform_real_distribution<double> across(-20e-3, 20e-3);
    double reaction = 0, transmitted = 0, point = 0;
    const int presses = 6;
    for (int i = 0; i < presses; ++i) {
      const Eigen::Vector3d tool(across(rng), across(rng), -1e-3);
      const std::vector<ContactQuery> contacts = find_tool_contacts(body, {{tool, 0}});
      const ToolReaction translation =
          contact_reactions_reference(body, contacts, {}, ContactModel::node_translation)[0];
      const ToolReaction constraint =
          contact_reactions_reference(body, contacts, {}, ContactModel::point_constraint)[0];
      const Eigen::Vector3d d = contacts[0].contact->displacement;
      const Eigen::Vector3d total = translation.nodal_forces.rowwise().sum();
      // Minimum energy: more constraint, more work for the same contact-point displacement.
      EXPECT_GE(d.dot(total), d.dot(-constraint.reaction) * (1 - 1e-9))
          << "divisions " << divisions;
      EXPECT_GT(d.dot(-constraint.reaction), 0);
      reaction += translation.reaction.z() / presses;
      transmitted += -total.z() / presses;
      point += constraint.reaction.z() / presses;
    }
    std::printf("  %-9d  %6.2f  %16.3f  %25.3f  %6.3f  %17.3f\n", divisions, 130.0 / divisions,
                reaction, transmitted, point, point / transmitted);
    scaled_translation.push_back(transmitted * divisions);
    scaled_point.push_back(point * divisions);
    EXPECT_NEAR(reaction / transmitted, 1.0 / 3.0, 0.12)
        << "the weighted reaction averages the nodal forces";
  }
  // Force x divisions: nearly mesh independent (within 35 % from 6 to 16 divisions).
  for (const std::vector<double>* scaled : {&scaled_translation, &scaled_point})
    for (double value : *scaled) EXPECT_NEAR(value / scaled->front(), 1.0, 0.35);
}

}  // namespace
}  // namespace cohaptic
