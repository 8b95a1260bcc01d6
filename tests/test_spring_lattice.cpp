// The `lattice:` mass-spring object (common/mass_spring/spring_lattice.h): the several-
// objects paper's front object A as scenes/objects/push.yaml declares it, checked against
// what a box lattice must be, counted independently of the builder: a spring on every
// distinct tetrahedron edge with the scene's k and k^d, the scene's node mass, the fixed
// selector's nodes held and no other, a closed outward surface enclosing the box's volume,
// and the sections its layers across the longest side; and the loader's errors
// (file:line: key.path: what was expected).
#include <gtest/gtest.h>

#include <set>

#include "common/mass_spring/tube_network.h"
#include "common/mesh/box_mesher.h"
#include "common/model/model.h"
#include "common/scene/load_scene.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

TEST(SpringLattice, PaperFrontObjectIsTheBoxLatticeTheSceneDeclares) {
  const Model model = build_model(load_scene(testing::source_path("scenes/objects/push.yaml")));
  const auto& body = std::get<MassSpringModel>(model.bodies.at(0));
  const MassSpringNetwork& network = body.network;
  ASSERT_EQ(network.node_count(), 4 * 5 * 3);
  for (int n = 0; n < network.node_count(); ++n) EXPECT_DOUBLE_EQ(network.mass[n], 0.05);

  const TetMesh mesh =
      make_box_mesh(Eigen::Vector3d(-0.0575, 0.01595, 0), Eigen::Vector3d(0.0575, 0.0989, 0.0575),
                    Eigen::Vector3i(3, 4, 2));
  std::set<std::pair<int, int>> edges;
  for (const auto& tet : mesh.tets)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        edges.insert(
            std::minmax(tet[static_cast<std::size_t>(a)], tet[static_cast<std::size_t>(b)]));
  ASSERT_EQ(network.springs.size(), edges.size());
  for (const Spring& s : network.springs) {
    EXPECT_TRUE(edges.count(std::minmax(s.a, s.b))) << s.a << "-" << s.b;
    EXPECT_DOUBLE_EQ(s.stiffness, 100);
    EXPECT_DOUBLE_EQ(s.damping, 0.10);
    EXPECT_NEAR(s.rest_length,
                (network.rest_positions.col(s.a) - network.rest_positions.col(s.b)).norm(), 1e-15);
  }
  for (int n = 0; n < network.node_count(); ++n)
    EXPECT_EQ(network.held[static_cast<std::size_t>(n)] != 0, network.rest_positions(2, n) == 0)
        << "node " << n;

  // 26 cell faces on the outside, two triangles each, enclosing the box.
  EXPECT_EQ(network.triangles.size(), 2u * 2 * (3 * 4 + 4 * 2 + 3 * 2));
  EXPECT_NEAR(enclosed_volume(network, network.rest_positions), 0.0575 * 0.0989 * 0.0575, 1e-15);

  // The longest side is y (4 divisions): 5 layers of 24.725 mm.
  ASSERT_EQ(body.section_count, 5);
  for (int n = 0; n < network.node_count(); ++n)
    EXPECT_EQ(body.section_of_node[static_cast<std::size_t>(n)],
              std::lround((network.rest_positions(1, n) - 0.01595) / 0.024725))
        << "node " << n;
  EXPECT_DOUBLE_EQ(network.parameters.node_damping, 0);
  EXPECT_EQ(network.parameters.gravity, Eigen::Vector3d::Zero());
}

const std::string kLatticeScene = R"(units: mm
objects:
  - name: A
    model: mass_spring
    lattice:
      box: {min: [0, 0, 0], size: [10, 20, 10], divisions: [1, 2, 1]}
      spring_stiffness: 100
      spring_damping: 0.1
      node_mass: 0.05
    fixed:
      - plane: {point: [0, 0, 0], normal: [0, 0, 1]}
tools: [{name: A}]
)";

std::string lattice_scene_with(const std::string& from, const std::string& to) {
  std::string text = kLatticeScene;
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

// The loader's (or the builder's) message for `text`, which must start with lattice.yaml:LINE:.
std::string lattice_error(const std::string& text) {
  try {
    build_model(parse_scene(text, "lattice.yaml"));
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no SceneError for:\n" << text;
  return "";
}

TEST(SpringLattice, SceneErrorsNameFileLineKeyAndExpectation) {
  EXPECT_EQ(
      std::get<MassSpringModel>(build_model(parse_scene(kLatticeScene, "lattice.yaml")).bodies[0])
          .network.node_count(),
      12);
  const std::pair<std::string, std::vector<std::string>> cases[] = {
      {lattice_scene_with("    lattice:\n",
                          "    tube: {centre_line: [[0, 0, 0], [1, 0, 0]], radius: 1, sections: "
                          "2}\n    lattice:\n"),
       {"lattice.yaml:3:", "objects[0]", "exactly one of tube or lattice"}},
      {lattice_scene_with("    fixed:\n",
                          "    material: {youngs_modulus: 1, density: 1}\n    fixed:\n"),
       {"lattice.yaml:10:", "objects[0].material", "a lattice takes no material"}},
      {lattice_scene_with("divisions: [1, 2, 1]", "divisions: [1, 0, 1]"),
       {"lattice.yaml:6:", "objects[0].lattice.box.divisions[1]", "an integer from 1 to 100"}},
      {lattice_scene_with("spring_damping: 0.1", "spring_damping: -0.1"),
       {"lattice.yaml:8:", "objects[0].lattice.spring_damping", ">= 0"}},
      {lattice_scene_with("node_mass: 0.05", "node_mass: 0"),
       {"lattice.yaml:9:", "objects[0].lattice.node_mass", "positive mass"}},
      {lattice_scene_with("spring_stiffness: 100", "spring_stiffness: 100\n      material: 1"),
       {"lattice.yaml:", "objects[0].lattice", "material", "spring_stiffness"}},
      {lattice_scene_with("point: [0, 0, 0], normal: [0, 0, 1]",
                          "point: [0, 0, 50], normal: [0, 0, 1]"),
       {"lattice.yaml:11:", "objects[0].fixed[0]", "selects no node"}},
  };
  for (const auto& [text, fragments] : cases) {
    const std::string message = lattice_error(text);
    for (const std::string& fragment : fragments)
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "message: " << message << "\nlacks: " << fragment;
  }
}

}  // namespace
}  // namespace cohaptic
