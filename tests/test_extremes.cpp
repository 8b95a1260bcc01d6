// The IR at the extremes a researcher will try, each with its stated expectation:
//   - Poisson's ratio 0 .. 0.499: equal to the full solve within a tolerance that grows
//     with the condition estimate the IR reports;
//   - E = 10 Pa and 1 GPa: forces scale exactly with E; the force limit holds;
//   - a sliver tetrahedron and a nearly degenerate contact triangle at the surface:
//     a warning naming the element, finite forces equal to the full solve;
//   - |B| = 0, 1, 300, 1000 and the whole movable surface: equal to the full solve;
//   - a tool deeper than the object is thick, exactly on an edge or a vertex: finite,
//     never above the limit, deterministic;
//   - a rigid obstacle: held nodes push, free nodes stay out, forces equal the full solve;
//     the free nodes about to reach it, and only those, are named for prefetching.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <memory>
#include <set>

#include "common/mesh/box_mesher.h"
#include "common/mesh/mesh_checks.h"
#include "common/mesh/write_gmsh.h"
#include "common/model/static_contact.h"
#include "common/scene/load_scene.h"
#include "common/sim/simulation.h"
#include "support/cube_scene.h"
#include "support/evaluate_static.h"
#include "support/measures.h"

namespace cohaptic {
namespace {

using testing::mm;

using Rig = testing::CubeRig;

testing::CubeSceneOptions cube(int divisions) {
  testing::CubeSceneOptions options;
  options.divisions = divisions;
  return options;
}

SimulationOptions options(double force_limit, int step_delay_nodes = 0,
                          ContactModel contact_model = ContactModel::node_translation) {
  SimulationOptions o;
  o.ir.force_limit = force_limit;
  o.ir.contact_model = contact_model;
  o.step_delay_nodes = step_delay_nodes;
  return o;
}

struct Comparison {
  Eigen::Vector3d ir = Eigen::Vector3d::Zero();
  Eigen::Vector3d reference = Eigen::Vector3d::Zero();
  double relative_error = 0;
  double condition = 0;
  int boundary_nodes = 0;
};

// One tool at `tool`: the IR's force against the full solve with the same held nodes.
Comparison compare(Rig& rig, const Eigen::Vector3d& tool, const SimulationOptions& o) {
  Simulation simulation(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(1), o);
  simulation.set_tool(0, tool);
  const StepReport report = simulation.step(0);
  Comparison c;
  c.ir = simulation.force(0).force;
  c.condition = simulation.ir(0)->condition_estimate;
  c.boundary_nodes = report.boundary_nodes;
  const HeldNodes held{simulation.condensation().boundary_nodes(),
                       simulation.boundary_displacement()};
  c.reference = contact_reactions_reference(rig.body, find_tool_contacts(rig.body, {{tool, 0}}),
                                            held, o.ir.contact_model)[0]
                    .reaction;
  c.relative_error = (c.ir - c.reference).norm() / c.reference.norm();
  return c;
}

const double kUnlimited = std::numeric_limits<double>::infinity();

TEST(Extremes, PoissonRatioFromZeroToNearlyIncompressible) {
  std::printf("  nu      |F| (N)   condition of L~   IR vs full solve\n");
  for (double nu : {0.0, 0.3, 0.45, 0.49, 0.499}) {
    testing::CubeSceneOptions scene;
    scene.divisions = 8;
    scene.poisson_ratio = nu;
    Rig rig(scene);
    for (ContactModel model : {ContactModel::node_translation, ContactModel::point_constraint}) {
      const Comparison c = compare(rig, mm(3, -4, -4), options(kUnlimited, 100, model));
      std::printf("  %-6g  %8.3f  %14.3g   %.2e (%s)\n", nu, c.ir.norm(), c.condition,
                  c.relative_error,
                  model == ContactModel::node_translation ? "translation" : "point");
      ASSERT_TRUE(c.ir.allFinite());
      // Stated tolerance: round-off amplified by the conditioning, never worse than 1e-9.
      EXPECT_LE(c.relative_error, std::max(1e-12 * c.condition, 1e-9)) << "nu " << nu;
    }
  }
}

TEST(Extremes, VerySoftAndVeryStiffTissueScaleExactlyAndRespectTheLimit) {
  testing::CubeSceneOptions scene;
  scene.divisions = 6;
  Rig middle(scene);
  const Eigen::Vector3d reference = compare(middle, mm(2, 3, -5), options(kUnlimited)).ir;
  for (double modulus : {10.0, 1e9}) {
    scene.youngs_modulus = modulus;
    Rig rig(scene);
    const Eigen::Vector3d force = compare(rig, mm(2, 3, -5), options(kUnlimited)).ir;
    EXPECT_LE((force / modulus - reference / 1e6).norm(), 1e-9 * (reference / 1e6).norm())
        << "E = " << modulus;
    // With the haptic limit the magnitude never exceeds it, whatever E.
    Simulation limited(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(1),
                       options(3.3));
    limited.set_tool(0, mm(2, 3, -5));
    limited.step(0);
    const ForceSample sample = limited.force(0);
    EXPECT_LE(sample.force.norm(), 3.3 * (1 + 1e-12));
    EXPECT_EQ(static_cast<bool>(sample.flags & kClamped), force.norm() > 3.3) << "E = " << modulus;
  }
}

TEST(Extremes, ASliverAndANearlyDegenerateContactTriangleAtTheSurface) {
  // A front-face node moved within the face, most of the way across one of its
  // triangles: that triangle becomes a thin needle and its tetrahedron a sliver.
  const std::string yaml = testing::cube_scene_yaml(cube(4));
  const Scene scene = parse_scene(yaml, "cube.yaml");
  const BoxMeshSpec& box = *single_elastic_object(scene).mesh.box;
  TetMesh mesh = make_box_mesh(box.min_corner, box.size, box.divisions);
  const int moved = 2 + 5 * (2 + 5 * 4);  // node (2, 2, 4): centre of the front face z = 0
  const Eigen::Vector3d target = mesh.nodes.col(3 + 5 * (3 + 5 * 4));  // node (3, 3, 4)
  mesh.nodes.col(moved) +=
      0.9995 * (target - mesh.nodes.col(moved)).cwiseProduct(Eigen::Vector3d(1, 0, 0));
  const MeshCheckReport report = check_tet_mesh(mesh);
  std::string warnings;
  for (const std::string& w : report.warnings) warnings += w;
  EXPECT_NE(warnings.find("sliver"), std::string::npos) << warnings;
  std::printf("  smallest dihedral angle %.3g deg: %s\n", report.min_dihedral_deg,
              warnings.c_str());
  EXPECT_LT(report.min_dihedral_deg, 1.0);

  // Build a model from the distorted mesh through a .msh file, as a user would.
  const std::string path = ::testing::TempDir() + "sliver_cube.msh";
  {
    TetMesh in_mm = mesh;
    in_mm.nodes /= 1e-3;
    write_gmsh41(path, in_mm);
  }
  const std::size_t mesh_line = yaml.find("mesh: {box:");
  const std::string file_yaml = yaml.substr(0, mesh_line) + "mesh: {file: " + path + "}" +
                                yaml.substr(yaml.find('\n', mesh_line));
  Rig rig(file_yaml);
  // Press on the needle triangle and around it.
  const Eigen::Vector3d needle_point =
      (mesh.nodes.col(moved) + target.cwiseProduct(Eigen::Vector3d(1, 0, 0)) +
       Eigen::Vector3d(0, target.y(), 0)) /
      2;
  for (const Eigen::Vector3d& at :
       {Eigen::Vector3d(needle_point.x(), mesh.nodes(1, moved) + 1e-5, -2e-3),
        Eigen::Vector3d(mesh.nodes(0, moved) - 1e-6, mesh.nodes(1, moved) + 1e-6, -2e-3)}) {
    for (ContactModel model : {ContactModel::node_translation, ContactModel::point_constraint}) {
      const Comparison c = compare(rig, at, options(kUnlimited, 0, model));
      ASSERT_TRUE(c.ir.allFinite());
      EXPECT_LE(c.relative_error, std::max(1e-12 * c.condition, 1e-9));
    }
  }
}

TEST(Extremes, FromNoHeldNodesToTheWholeSurface) {
  Rig rig(testing::CubeSceneOptions{});
  int movable = 0;
  for (int node : rig.body.surface.nodes) movable += rig.body.dofs.fixed_axes[node] != kAllAxes;
  const int whole_surface = movable - 3;  // all but the contact triangle
  std::printf("  |B|     |F| (N)    IR vs full solve   condition of L~\n");
  double previous = 0;
  for (int held : {0, 1, 300, whole_surface}) {
    SimulationOptions o = options(kUnlimited, held);
    o.ir.patch_rings = 0;  // the patch is the contact triangle alone: every other node may be held
    const Comparison c = compare(rig, mm(1, 2, -2), o);
    std::printf("  %-6d %8.3f   %.2e           %.3g\n", c.boundary_nodes, c.ir.norm(),
                c.relative_error, c.condition);
    EXPECT_EQ(c.boundary_nodes, held);
    EXPECT_LE(c.relative_error, 1e-9);
    EXPECT_GT(c.ir.norm(), previous) << "holding more nodes stiffens the object";
    previous = c.ir.norm();
  }
  // 1,000 held nodes need a finer cube: the paper's has 584 movable surface nodes.
  Rig fine(cube(16));
  const Comparison c = compare(fine, mm(1, 2, -2), options(kUnlimited, 1000));
  std::printf("  %-6d %8.3f   %.2e           %.3g   (16-division cube)\n", c.boundary_nodes,
              c.ir.norm(), c.relative_error, c.condition);
  EXPECT_EQ(c.boundary_nodes, 1000);
  EXPECT_LE(c.relative_error, 1e-9);
}

TEST(Extremes, ToolsDeeperThanTheObjectOnEdgesAndOnVertices) {
  Rig rig(testing::CubeSceneOptions{});
  const Model& model = *rig.model;
  const ElasticBody& body = single_elastic_body(model);
  Simulation simulation(single_elastic_body(model), model.obstacles, *rig.columns,
                        std::vector<ToolSpec>(1), options(3.3));
  simulation.set_tool(0, mm(1, 2, -1));
  simulation.step(0);
  const PreparedIR& prepared = *simulation.ir(0);
  // Pushed through the whole cube (130 mm deep) and beyond: still a bounded, finite force.
  for (double depth : {130.0, 200.0, 1e6}) {
    const ForceSample sample = testing::evaluate_static(prepared, mm(1, 2, -depth), {});
    EXPECT_TRUE(sample.force.allFinite());
    EXPECT_NEAR(sample.force.norm(), 3.3, 1e-9) << "depth " << depth;
    EXPECT_TRUE(sample.flags & kClamped);
  }
  // Exactly under a patch vertex and an edge midpoint: finite, deterministic, and the
  // same triangle as the server picks (ties go to the lower surface index on both sides).
  const IrTriangle& tri = condensed_fem(prepared.ir).patch[0];
  const Eigen::Vector3d vertex = condensed_fem(prepared.ir).rest_positions.col(tri.nodes[0]);
  const Eigen::Vector3d edge =
      (vertex + condensed_fem(prepared.ir).rest_positions.col(tri.nodes[1])) / 2;
  for (const Eigen::Vector3d& on : {vertex, edge}) {
    const Eigen::Vector3d tool = on - 2e-3 * tri.normal;
    const ForceSample a = testing::evaluate_static(prepared, tool, {});
    const ForceSample b = testing::evaluate_static(prepared, tool, {});
    ASSERT_TRUE(a.force.allFinite());
    EXPECT_EQ(a.force, b.force);
    EXPECT_EQ(a.triangle, b.triangle);
    const int server_triangle =
        nearest_triangle(body.mesh, body.surface, body.normals, body.touchable_triangles, tool)
            .triangle;
    EXPECT_EQ(condensed_fem(prepared.ir).patch[a.triangle].surface_index, server_triangle);
  }
}

TEST(Extremes, ARigidWallCatchesTheBulge) {
  // The front face is pressed in; the side x = +65 mm bulges out by a few hundredths of a
  // millimetre near the front and meets a wall 0.005 mm away.
  testing::CubeSceneOptions scene;
  scene.divisions = 8;
  scene.obstacles = "{name: wall, plane: {point: [65.005, 0, 0], normal: [-1, 0, 0]}}";
  Rig rig(scene);
  const Model& model = *rig.model;
  const ElasticBody& body = single_elastic_body(model);
  Rig free_rig(cube(8));
  const Eigen::Vector3d tool = mm(40, 0, -8);
  for (ContactModel contact_model :
       {ContactModel::node_translation, ContactModel::point_constraint}) {
    Simulation simulation(single_elastic_body(model), model.obstacles, *rig.columns,
                          std::vector<ToolSpec>(1), options(kUnlimited, 0, contact_model));
    simulation.set_tool(0, tool);
    StepReport report;
    for (int step = 0; step < 6; ++step) report = simulation.step(0.001 * step);
    ASSERT_GT(report.obstacle_nodes, 0) << "the bulge should reach the wall";
    const Eigen::Vector3d ir_force = simulation.force(0).force;
    const HeldNodes held{simulation.condensation().boundary_nodes(),
                         simulation.boundary_displacement()};
    Eigen::VectorXd u;
    const Eigen::Vector3d reference =
        contact_reactions_reference(body, find_tool_contacts(body, {{tool, 0}}), held,
                                    contact_model, &u)[0]
            .reaction;
    EXPECT_LE((ir_force - reference).norm(), 1e-9 * reference.norm());
    // Free surface nodes stay on the allowed side; held nodes sit on the wall and are pushed.
    const StateSolution state = simulation.solve();
    for (int node : body.surface.nodes)
      EXPECT_LE(body.mesh.nodes(0, node) + u[3 * node], 65.005e-3 + 1e-9) << "node " << node;
    for (std::size_t b = 0, dof = 0; b < held.nodes.size(); ++b) {
      const int node = held.nodes[b];
      EXPECT_NEAR(body.mesh.nodes(0, node) + held.displacement[b].x(), 65.005e-3, 1e-12);
      Eigen::Vector3d force = Eigen::Vector3d::Zero();
      for (int axis = 0; axis < 3; ++axis)
        if (!body.dofs.is_fixed(node, axis))
          force[axis] = state.boundary_forces[static_cast<Eigen::Index>(dof++)];
      EXPECT_LE(force.x(), 1e-12) << "the wall pushes (towards -x), it never pulls";
    }
    // The wall stiffens the object.
    Simulation free(free_rig.body, free_rig.model->obstacles, *free_rig.columns,
                    std::vector<ToolSpec>(1), options(kUnlimited, 0, contact_model));
    free.set_tool(0, tool);
    free.step(0);
    EXPECT_GT(ir_force.norm(), free.force(0).force.norm());
    std::printf("  %s: %d nodes held by the wall, |F| %.4f N (free %.4f N)\n",
                contact_model == ContactModel::node_translation ? "translation" : "point",
                report.obstacle_nodes, ir_force.norm(), free.force(0).force.norm());
  }
}

TEST(Extremes, TheNodesAboutToReachAWallAreNamedForPrefetching) {
  // A wall 0.5 mm beside the x = +65 mm side: its nodes are within the 1 mm that
  // nodes_near_obstacles() reports, the rest of the surface is not. The rig's columns
  // start empty, so these nodes lack their columns until the simulation needs them.
  testing::CubeSceneOptions scene;
  scene.divisions = 6;
  scene.obstacles = "{name: wall, plane: {point: [65.5, 0, 0], normal: [-1, 0, 0]}}";
  Rig rig(scene);
  const ElasticBody& body = rig.body;
  SimulationOptions o = options(kUnlimited);
  ASSERT_EQ(o.near_obstacle_distance, 1e-3);
  Simulation simulation(body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(1), o);
  simulation.set_tool(
      0, mm(30, 0, -4));  // the side bulges towards the wall by a few tenths of a millimetre
  const StepReport report = simulation.step(0);
  EXPECT_GT(report.obstacle_nodes, 0) << "the bulge should reach the wall";
  std::vector<int> named;
  for (const NodeDistance& near : simulation.nodes_near_obstacles()) named.push_back(near.node);
  const Eigen::Matrix3Xd u = simulation.displacement_of(named);
  for (std::size_t k = 0; k < named.size(); ++k) {
    const int node = named[k];
    EXPECT_EQ(body.mesh.nodes(0, node), 65e-3)
        << "node " << node << " is not on the side by the wall";
    // A plane's estimate is exact: the gap left by the bulge.
    EXPECT_NEAR(simulation.nodes_near_obstacles()[k].distance,
                65.5e-3 - (65e-3 + u(0, static_cast<Eigen::Index>(k))), 1e-12)
        << "node " << node;
  }
  // Every free node of that side without columns is named, once.
  const std::set<int> named_set(named.begin(), named.end());
  EXPECT_EQ(named_set.size(), named.size());
  int side = 0;
  for (int node : body.surface.nodes) {
    if (body.mesh.nodes(0, node) != 65e-3 || body.dofs.fixed_axes[node] == kAllAxes) continue;
    ++side;
    if (!rig.columns->has_column(node)) {
      EXPECT_TRUE(named_set.count(node)) << "node " << node << " not named";
    }
  }
  EXPECT_GT(named_set.size(), static_cast<std::size_t>(side) / 2);
}

}  // namespace
}  // namespace cohaptic
