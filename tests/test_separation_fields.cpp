// The separation body's precomputed force-deflection fields:
// the interface of two boxes, the fitted fields against full sparse FEM solves of the
// two meshes with tied pairs merged (no condensation), the polynomial fit, the disk
// cache, and the area blend of Eq. 2.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <filesystem>
#include <fstream>
#include <random>

#include "common/separation/interface_regions.h"
#include "common/separation/polynomial_fit.h"
#include "common/separation/pull_loop.h"
#include "common/separation/separation_field_cache.h"
#include "common/separation/separation_force.h"
#include "common/separation/tied_system.h"
#include "common/separation/separation_setup.h"
#include "common/util/error.h"
#include "support/scratch_directory.h"

namespace cohaptic {
namespace {

using testing::ScratchDirectory;

namespace fs = std::filesystem;

// A small pair of layers: 8 x 8 cells of 5 mm, quick to solve in full.
TwoLayerBoxes small_boxes() {
  TwoLayerBoxes boxes;
  boxes.divisions = {8, 8};
  boxes.pulled_layers = 2;
  boxes.base_layers = 2;
  boxes.pulled_material.youngs_modulus = 40e3;  // a softer flap on a stiffer bed
  return boxes;
}

double relative(const Eigen::Vector3d& value, const Eigen::Vector3d& reference) {
  return (value - reference).norm() / reference.norm();
}

TEST(SeparationInterface, TwoBoxesShareTheirConformingFace) {
  const TwoLayerBoxes boxes = small_boxes();
  const SeparationBodies bodies = make_two_layer_boxes(boxes);
  SeparationInterface interface = find_interface(bodies, 1e-9);
  EXPECT_EQ(interface.node_count(), 9 * 9);
  EXPECT_EQ(interface.triangle_count(), 2 * 8 * 8);
  int rim_edges = 0;
  for (int t = 0; t < interface.triangle_count(); ++t) {
    const Triangle& tri = interface.triangles[t];
    const Eigen::Vector3d a = interface.positions.col(tri[0]);
    const Eigen::Vector3d normal =
        (interface.positions.col(tri[1]) - a).cross(interface.positions.col(tri[2]) - a);
    EXPECT_GT(normal.normalized().z(), 1 - 1e-12)
        << "triangle " << t << " does not face the pulled layer";
    for (int k = 0; k < 3; ++k) {
      EXPECT_DOUBLE_EQ(interface.positions(2, tri[k]), 0.0);
      rim_edges += interface.open_rim[t] >> k & 1;
    }
  }
  EXPECT_EQ(rim_edges, 4 * 8);
  for (int k = 0; k < interface.node_count(); ++k)
    EXPECT_EQ(bodies.pulled.mesh.nodes.col(interface.pulled_nodes[k]),
              bodies.base.mesh.nodes.col(interface.base_nodes[k]));
  seal_rim_edges(interface,
                 [&](int node) { return interface.positions(0, node) > boxes.size.x() - 1e-9; });
  rim_edges = 0;
  for (int t = 0; t < interface.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) rim_edges += interface.open_rim[t] >> k & 1;
  EXPECT_EQ(rim_edges, 3 * 8);

  SeparationBodies apart = bodies;
  apart.pulled.mesh.nodes.row(2).array() += 1e-3;
  try {
    find_interface(apart, 1e-9);
    FAIL() << "bodies 1 mm apart share no interface";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("share no boundary triangle"), std::string::npos)
        << e.what();
  }
}

// Every field against full sparse solves of the merged meshes (an independent path: no
// condensation, no multipliers), at the deflections the fit sampled and at others.
TEST(SeparationFields, ReproduceTheFullSparseSolveInEveryState) {
  const TwoLayerBoxes boxes = small_boxes();
  const SeparationBodies bodies = make_two_layer_boxes(boxes);
  const SeparationInterface interface = find_interface(bodies, 1e-9);
  const double spacing = boxes.size.x() / boxes.divisions.x();
  // Degree 2 through two samples per axis interpolates; degree 5 through 9 (8 non-zero) is a
  // least-squares fit. Linear FEM is exact for both.
  for (auto [degree, samples] : {std::pair{2, 2}, std::pair{5, 9}}) {
    FieldSettings settings;
    settings.degree = degree;
    settings.samples_per_axis = samples;
    settings.footprint_radii = {0.0, 1.1 * spacing};  // a point and a node with its 4 neighbours
    FieldPrecomputeReport report;
    const SeparationFields fields =
        precompute_separation_fields(bodies, interface, settings, &report);
    const SeparationPatch patch = make_separation_patch(interface, fields, SeparationSettings{});
    EXPECT_EQ(report.field_count, 81 * 2 * 3);
    for (double e : report.max_fit_error) EXPECT_LT(e, 1e-12);

    const NodeRegions regions = node_regions(interface.triangles, interface.node_count());
    const std::vector<double> abscissae = chebyshev_abscissae(samples, settings.max_deflection);
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> uniform(-settings.max_deflection,
                                                   settings.max_deflection);
    const auto at = [&](double x, double y) {
      int best = 0;
      for (int k = 1; k < interface.node_count(); ++k)
        if ((interface.positions.col(k) - Eigen::Vector3d(x, y, 0)).norm() <
            (interface.positions.col(best) - Eigen::Vector3d(x, y, 0)).norm())
          best = k;
      return best;
    };
    const int corner = at(0, 0), rim = at(0.02, 0);
    for (int node : {corner, rim, at(0.02, 0.02), at(0.025, 0.015)}) {
      const std::vector<int> released = nodes_released_with(regions, interface.triangles, node);
      ASSERT_EQ(released, std::vector<int>{node});
      for (int s = 0; s < kFieldStates; ++s) {
        std::vector<bool> tied(static_cast<std::size_t>(interface.node_count()), s != 2);
        if (s == 1) tied[node] = false;
        const TiedSystem system = tied_system(bodies, interface, tied);
        for (int j = 0; j < 2; ++j) {
          const double* block = patch.field(node, j, static_cast<FieldState>(s));
          const Eigen::Map<const Eigen::Matrix3d> frame(block);
          std::vector<Eigen::Vector3d> deltas;
          for (int a = 0; a < 3; ++a)
            for (double sample : abscissae)
              if (sample != 0) deltas.push_back(sample * frame.col(a));
          for (int r = 0; r < 3; ++r) deltas.emplace_back(uniform(rng), uniform(rng), uniform(rng));
          const std::vector<int> footprint =
              tool_footprint(interface, node, settings.footprint_radii[j]);
          EXPECT_EQ(footprint.size(), j == 0 ? 1u : (node == corner ? 3u : node == rim ? 4u : 5u));
          const std::vector<Eigen::Vector3d> full =
              footprint_forces(system, interface, footprint, deltas);
          for (std::size_t i = 0; i < deltas.size(); ++i)
            EXPECT_LT(
                relative(field_value(patch, node, j, static_cast<FieldState>(s), deltas[i]).force,
                         full[i]),
                1e-9)
                << "degree " << degree << " node " << node << " tool node " << j << " state "
                << field_state_name(static_cast<FieldState>(s)) << " deflection "
                << deltas[i].transpose();
        }
      }
    }
  }
}

// Connecting more can only stiffen (adding constraints): at every deflection the fields'
// energies are ordered U(F) >= U(F-bar) >= U(F^e), which is what makes fracture passive.
TEST(SeparationFields, MoreConnectionStoresMoreEnergy) {
  const TwoLayerBoxes boxes = small_boxes();
  const SeparationSetup setup = make_two_layer_setup(boxes, FieldSettings{}, SeparationSettings{});
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(-0.004, 0.004);
  for (int node = 0; node < setup.patch.node_count(); ++node)
    for (int trial = 0; trial < 4; ++trial) {
      const Eigen::Vector3d delta(uniform(rng), uniform(rng), uniform(rng));
      const double connected =
          field_value(setup.patch, node, 0, FieldState::connected, delta).energy;
      const double local =
          field_value(setup.patch, node, 0, FieldState::locally_separated, delta).energy;
      const double separated =
          field_value(setup.patch, node, 0, FieldState::separated, delta).energy;
      EXPECT_GE(connected, local * (1 - 1e-12)) << "node " << node;
      EXPECT_GE(local, separated * (1 - 1e-12)) << "node " << node;
      EXPECT_GT(separated, 0) << "node " << node;
      // The potential is the force's: U(delta) = 1/2 F(delta) . delta for a linear field.
      const FieldValue v = field_value(setup.patch, node, 0, FieldState::connected, delta);
      EXPECT_NEAR(v.energy, 0.5 * v.force.dot(delta), 1e-12 * v.energy);
    }
}

TEST(PolynomialFit, InterpolatesItsDegreeAndLeavesAnOrthogonalResidualOtherwise) {
  // A cubic through the origin, sampled at 3 points (interpolation) and at 8 (least squares).
  const double c[3] = {120.0, -4e3, 2.5e6};  // N/m, N/m^2, N/m^3
  for (int count : {4, 8}) {
    std::vector<double> s = chebyshev_abscissae(count, 0.01);
    if (count == 4) s.pop_back();  // three abscissae for three coefficients
    std::vector<double> f;
    for (double x : s) f.push_back(c[0] * x + c[1] * x * x + c[2] * x * x * x);
    const std::vector<double> fit = fit_polynomial_through_origin(s, f, 3);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(fit[k], c[k], 1e-9 * std::abs(c[k])) << "count " << count;
    for (std::size_t i = 0; i < s.size(); ++i)
      EXPECT_NEAR(polynomial_value(fit.data(), 3, s[i]), f[i], 1e-9 * std::abs(f[i]));
  }
  // Not a polynomial: the least-squares residual is orthogonal to every basis column, and
  // small for a smooth stiffening law over a modest range (stated tolerance: 1 % of the
  // largest force for a degree-5 fit of an exponential).
  const std::vector<double> s = chebyshev_abscissae(12, 0.005);
  std::vector<double> f;
  for (double x : s) f.push_back(0.2 * (std::exp(x / 0.004) - 1));
  const std::vector<double> fit = fit_polynomial_through_origin(s, f, 5);
  double largest = 0, worst = 0;
  for (int k = 1; k <= 5; ++k) {
    double dot = 0, scale = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const double column = std::pow(s[i] / 0.005, k);
      dot += column * (f[i] - polynomial_value(fit.data(), 5, s[i]));
      scale += std::abs(column * f[i]);
    }
    EXPECT_LT(std::abs(dot), 1e-12 * scale) << "column " << k;
  }
  for (std::size_t i = 0; i < s.size(); ++i) {
    largest = std::max(largest, std::abs(f[i]));
    worst = std::max(worst, std::abs(polynomial_value(fit.data(), 5, s[i]) - f[i]));
  }
  EXPECT_LT(worst, 0.01 * largest);
  // The integral is the antiderivative: its derivative by central difference is the value.
  const double h = 1e-7, x = 0.003;
  EXPECT_NEAR(
      (polynomial_integral(fit.data(), 5, x + h) - polynomial_integral(fit.data(), 5, x - h)) /
          (2 * h),
      polynomial_value(fit.data(), 5, x), 1e-6 * std::abs(polynomial_value(fit.data(), 5, x)));

  try {
    fit_polynomial_through_origin(chebyshev_abscissae(3, 0.01), std::vector<double>{1, 0, -1}, 3);
    FAIL() << "three coefficients from two non-zero abscissae (the third Chebyshev point of three "
              "is 0)";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("distinct non-zero samples"), std::string::npos)
        << e.what();
  }
}

TEST(SeparationFieldCache, RoundTripsBitForBitAndRebuildsWhenCorrupt) {
  ScratchDirectory scratch;
  const TwoLayerBoxes boxes = small_boxes();
  FieldSettings settings;
  settings.degree = 5;
  settings.samples_per_axis = 10;
  const SeparationSetup first =
      make_two_layer_setup(boxes, settings, SeparationSettings{}, scratch.path);
  EXPECT_FALSE(first.fields_from_cache);
  EXPECT_GT(first.report.total_seconds(), 0);
  const SeparationSetup second =
      make_two_layer_setup(boxes, settings, SeparationSettings{}, scratch.path);
  ASSERT_TRUE(second.fields_from_cache);
  EXPECT_EQ(second.fields.values, first.fields.values);  // bit for bit
  EXPECT_EQ(second.fields.degree, 5);
  // The patch built from stored fields evaluates the same forces.
  const Eigen::Vector3d delta(0.001, -0.002, 0.003);
  EXPECT_EQ(field_value(second.patch, 40, 0, FieldState::locally_separated, delta).force,
            field_value(first.patch, 40, 0, FieldState::locally_separated, delta).force);

  const Digest key = separation_fields_key(first.bodies, first.interface, settings);
  const fs::path file = separation_fields_file(scratch.path, key);
  ASSERT_TRUE(fs::exists(file));
  {  // flip one byte in the middle of the values
    std::fstream io(file, std::ios::in | std::ios::out | std::ios::binary);
    io.seekp(static_cast<std::streamoff>(fs::file_size(file) / 2));
    io.put('\x5a');
  }
  EXPECT_EQ(load_separation_fields(file, key).problem,
            "checksum mismatch (truncated or corrupted)");
  const CachedSeparationFields rebuilt =
      cached_separation_fields(scratch.path, first.bodies, first.interface, settings);
  EXPECT_FALSE(rebuilt.from_cache);
  EXPECT_EQ(rebuilt.rebuilt_because, "checksum mismatch (truncated or corrupted)");
  EXPECT_EQ(rebuilt.fields.values, first.fields.values);
  EXPECT_TRUE(load_separation_fields(file, key).loaded);

  fs::resize_file(file, 100);
  EXPECT_FALSE(load_separation_fields(file, key).loaded);
  // Anything that changes the fields changes the key.
  FieldSettings other = settings;
  other.max_deflection *= 2;
  EXPECT_NE(separation_fields_key(first.bodies, first.interface, other), key);
  SeparationBodies stiffer = first.bodies;
  stiffer.base.material.youngs_modulus *= 1.01;
  EXPECT_NE(separation_fields_key(stiffer, first.interface, settings), key);
  EXPECT_EQ(load_separation_fields(scratch.path / "none.bin", key).problem, "no cache file");
}

// Eq. 2: fully connected gives F, fully separated F^e, D_n alone separated F-bar, and the
// three weights sum to one (a patch whose three fields are equal gives that field for any
// areas). Algorithm V.2: at a vertex the nodal field, inside the triangles the weighted sum.
TEST(SeparationBlend, PureStatesWeightsAndInterpolation) {
  const SeparationSetup setup =
      make_two_layer_setup(small_boxes(), FieldSettings{}, SeparationSettings{});
  const SeparationPatch& patch = setup.patch;
  const Eigen::Vector3d delta(0.0012, -0.0007, 0.0021);
  const int node = 40;
  const auto pure = [&](FieldState s) { return field_value(patch, node, 0, s, delta).force; };
  EXPECT_EQ(nodal_separation_field(patch, node, 0, 0, 0, delta).force, pure(FieldState::connected));
  EXPECT_LT(relative(nodal_separation_field(patch, node, 0, 1, 0, delta).force,
                     pure(FieldState::locally_separated)),
            1e-15);
  EXPECT_LT(relative(nodal_separation_field(patch, node, 0, 0.3, 1, delta).force,
                     pure(FieldState::separated)),
            1e-15);
  const Eigen::Vector3d mixed =
      0.8 * (0.7 * pure(FieldState::connected) + 0.3 * pure(FieldState::locally_separated)) +
      0.2 * pure(FieldState::separated);
  EXPECT_LT(relative(nodal_separation_field(patch, node, 0, 0.3, 0.2, delta).force, mixed), 1e-14);

  SeparationPatch equal = patch;
  const std::size_t block = static_cast<std::size_t>(SeparationFields::block_size(equal.degree));
  for (int n = 0; n < equal.node_count(); ++n) {
    const double* connected = equal.field(n, 0, FieldState::connected);
    for (FieldState s : {FieldState::locally_separated, FieldState::separated})
      std::copy(connected, connected + block, const_cast<double*>(equal.field(n, 0, s)));
  }
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> share(0, 1);
  for (int trial = 0; trial < 20; ++trial)
    EXPECT_LT(relative(nodal_separation_field(equal, node, 0, share(rng), share(rng), delta).force,
                       pure(FieldState::connected)),
              1e-14);

  // The state's shares: D_n separated gives A(R-bar_n) = 1 and A(S-bar) = |D_n| / |C|.
  SeparationState state = make_separation_state(patch);
  const std::span<const int> region = patch.regions.of(node);
  separate_triangles(patch, state, std::vector<int>(region.begin(), region.end()));
  EXPECT_DOUBLE_EQ(local_separated_share(patch, state, node), 1.0);
  EXPECT_NEAR(global_separated_share(patch, state), patch.region_areas[node] / patch.interface_area,
              1e-15);

  ContactPoint point;
  point.triangle = region.front();
  const Triangle& tri = patch.triangles[point.triangle];
  const ContactAreas areas = contact_areas(patch, state, point.triangle);
  point.weights = Eigen::Vector3d(tri[0] == node, tri[1] == node, tri[2] == node);
  const int k = tri[0] == node ? 0 : tri[1] == node ? 1 : 2;
  EXPECT_EQ(contact_field(patch, point, areas, delta).force,
            nodal_separation_field(patch, node, 0, areas.local_separated[k], areas.global_separated,
                                   delta)
                .force);
  point.weights = Eigen::Vector3d(0.2, 0.5, 0.3);
  Eigen::Vector3d expected = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i)
    expected +=
        point.weights[i] * nodal_separation_field(patch, tri[i], 0, areas.local_separated[i],
                                                  areas.global_separated, delta)
                               .force;
  EXPECT_LT(relative(contact_field(patch, point, areas, delta).force, expected), 1e-14);
}

// Over a tool triangle: tool nodes with different footprints, weighted by beta. A wider
// footprint holds more of the surface: it is stiffer in every state.
TEST(SeparationBlend, InterpolatesOverTheToolTriangle) {
  FieldSettings settings;
  settings.footprint_radii = {0.0, 0.0051, 0.0072};  // the node; with 4 neighbours; with 8
  const SeparationSetup setup = make_two_layer_setup(small_boxes(), settings, SeparationSettings{});
  const SeparationPatch& patch = setup.patch;
  const Eigen::Vector3d delta(0.0005, 0.0003, 0.002);
  const int node = 40;
  ContactPoint point = contact_at_node(patch, node);
  point.tool_nodes = {0, 1, 2};
  point.tool_weights = Eigen::Vector3d(0.2, 0.3, 0.5);
  SeparationState state = make_separation_state(patch);
  separate_triangles(patch, state, std::vector<int>{patch.regions.of(node).front()});
  const ContactAreas areas = contact_areas(patch, state, point.triangle);
  const int k = patch.triangles[point.triangle][0] == node   ? 0
                : patch.triangles[point.triangle][1] == node ? 1
                                                             : 2;
  Eigen::Vector3d expected = Eigen::Vector3d::Zero();
  for (int j = 0; j < 3; ++j)
    expected +=
        point.tool_weights[j] * nodal_separation_field(patch, node, j, areas.local_separated[k],
                                                       areas.global_separated, delta)
                                    .force;
  EXPECT_LT(relative(contact_field(patch, point, areas, delta).force, expected), 1e-14);
  for (int s = 0; s < kFieldStates; ++s)
    for (int j = 1; j < 3; ++j)
      EXPECT_GT(field_value(patch, node, j, static_cast<FieldState>(s), delta).energy,
                field_value(patch, node, j - 1, static_cast<FieldState>(s), delta).energy)
          << field_state_name(static_cast<FieldState>(s)) << " tool node " << j;
}

}  // namespace
}  // namespace cohaptic
