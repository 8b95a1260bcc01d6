// Linear FEM against independent answers: a second element formulation, invariants of K,
// the patch test, uniaxial compression (exact) and the cantilever against beam theory.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cstdio>
#include <random>
#include <thread>

#include "common/fem/assemble_stiffness.h"
#include "common/fem/deferred_cholesky.h"
#include "common/fem/sparse_cholesky.h"
#include "common/fem/static_solve.h"
#include "common/fem/tet_stiffness.h"
#include "common/mesh/boundary_surface.h"
#include "common/mesh/box_mesher.h"
#include "common/model/model.h"
#include "common/scene/load_scene.h"
#include "common/util/error.h"
#include "support/independent_fem.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

const LinearElasticMaterial kSoft{1.0e6, 0.4};

TEST(TetStiffness, EqualsTheLameFormOnRandomElements) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::Matrix<double, 3, 4> corners;
    for (int i = 0; i < 12; ++i) corners(i % 3, i / 3) = coordinate(rng);
    double volume = 0;
    tet_shape_gradients(corners, volume);
    if (volume < 0) corners.col(2).swap(corners.col(3));
    const TetStiffness k = tet_stiffness(corners, elasticity_matrix(kSoft));
    const auto expected =
        testing::independent_tet_stiffness(corners, kSoft.youngs_modulus, kSoft.poisson_ratio);
    EXPECT_LE((k - expected).norm(), 1e-12 * expected.norm()) << "trial " << trial;
  }
}

TEST(Stiffness, SymmetricWithTheSixRigidBodyModesInItsNullSpace) {
  const TetMesh mesh = testing::distorted_box_mesh(0.05, 2, 0.2, 3);
  const SparseMatrix k = assemble_stiffness(mesh, kSoft);
  const Eigen::MatrixXd dense(k);
  EXPECT_LE((dense - dense.transpose()).norm(), 1e-14 * dense.norm());

  // Three translations and three infinitesimal rotations.
  const int n = mesh.node_count();
  Eigen::MatrixXd modes = Eigen::MatrixXd::Zero(3 * n, 6);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d x = mesh.nodes.col(i);
    for (int a = 0; a < 3; ++a) {
      modes(3 * i + a, a) = 1;
      modes.block<3, 1>(3 * i, 3 + a) = Eigen::Vector3d::Unit(a).cross(x);
    }
  }
  for (int m = 0; m < 6; ++m)
    EXPECT_LE((dense * modes.col(m)).norm(), 1e-12 * dense.norm() * modes.col(m).norm())
        << "mode " << m;

  // Exactly six zero eigenvalues: rank 3N - 6.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(dense);
  const Eigen::VectorXd values = eigen.eigenvalues();  // ascending
  for (int i = 0; i < 6; ++i) EXPECT_LE(std::abs(values[i]), 1e-10 * values.maxCoeff());
  EXPECT_GT(values[6], 1e-6 * values.maxCoeff());
}

TEST(Stiffness, PositiveDefiniteOnceFixedAndCholmodAgreesWithADenseSolve) {
  const TetMesh mesh = testing::distorted_box_mesh(0.05, 3, 0.2, 5);
  const SparseMatrix k = assemble_stiffness(mesh, kSoft);
  std::vector<AxisMask> fixed(static_cast<std::size_t>(mesh.node_count()), 0);
  for (int i = 0; i < mesh.node_count(); ++i)
    if (mesh.nodes(2, i) < 1e-12) fixed[i] = kAllAxes;
  const DofMap dofs = make_dof_map(fixed);
  const SparseMatrix k_ff = restrict_to_dofs(k, dofs.free_dofs);
  const Eigen::MatrixXd dense(k_ff);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(dense);
  EXPECT_GT(eigen.eigenvalues().minCoeff(), 0);

  const SparseCholesky factor(k_ff);
  EXPECT_TRUE(factor.is_supernodal());
  std::mt19937 rng(1);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd rhs(k_ff.rows(), 3);
  for (Eigen::Index i = 0; i < rhs.size(); ++i) rhs.data()[i] = normal(rng);
  const Eigen::MatrixXd x = factor.solve(rhs);
  const Eigen::MatrixXd expected = dense.ldlt().solve(rhs);
  EXPECT_LE((x - expected).norm(), 1e-9 * expected.norm());

  // The factor is immutable: threads solving at once, each with its own workspace reused
  // over many solves, get the single-threaded answer bit for bit.
  std::vector<Eigen::MatrixXd> answers(4);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < answers.size(); ++t)
    threads.emplace_back([&, t] {
      CholeskyWorkspace workspace;
      for (int repeat = 0; repeat < 50; ++repeat)
        answers[t] = factor.solve(rhs * double(t + 1), workspace);
    });
  for (std::thread& thread : threads) thread.join();
  for (std::size_t t = 0; t < answers.size(); ++t)
    EXPECT_EQ(answers[t], factor.solve(rhs * double(t + 1))) << "thread " << t;
}

TEST(SparseCholesky, AnIndefiniteMatrixIsATypedErrorNamingTheRow) {
  const TetMesh mesh = make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(1),
                                     Eigen::Vector3i::Constant(2));
  const SparseMatrix k = -assemble_stiffness(mesh, kSoft);  // negative definite once fixed
  std::vector<AxisMask> fixed(static_cast<std::size_t>(mesh.node_count()), 0);
  fixed[0] = fixed[1] = fixed[3] = kAllAxes;
  const DofMap dofs = make_dof_map(fixed);
  try {
    SparseCholesky factor(restrict_to_dofs(k, dofs.free_dofs), [&](int row) {
      return "node " + std::to_string(mesh.node_tags[dofs.free_dofs[row] / 3]);
    });
    FAIL() << "no error";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("not positive definite"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("first failure at node "), std::string::npos) << e.what();
  }
}

TEST(DeferredCholesky, FactorsOnceOnFirstUseSharedByCopiesAndThreadsAndEqualsTheDirectFactor) {
  const TetMesh mesh = testing::distorted_box_mesh(0.05, 3, 0.2, 9);
  std::vector<AxisMask> fixed(static_cast<std::size_t>(mesh.node_count()), 0);
  for (int i = 0; i < mesh.node_count(); ++i)
    if (mesh.nodes(2, i) < 1e-12) fixed[i] = kAllAxes;
  const SparseMatrix k_ff =
      restrict_to_dofs(assemble_stiffness(mesh, kSoft), make_dof_map(fixed).free_dofs);
  const DeferredCholesky deferred(k_ff, {});
  const DeferredCholesky copy = deferred;
  EXPECT_FALSE(deferred.factored());
  EXPECT_EQ(deferred.factor_ms(), 0);

  // Threads asking at once all get the one factor the first of them made.
  std::vector<const SparseCholesky*> seen(4, nullptr);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < seen.size(); ++t)
    threads.emplace_back([&, t] { seen[t] = &(t % 2 ? copy : deferred).factor(); });
  for (std::thread& thread : threads) thread.join();
  for (const SparseCholesky* factor : seen) EXPECT_EQ(factor, seen.front());
  EXPECT_TRUE(copy.factored());
  EXPECT_GT(deferred.factor_ms(), 0);

  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Ones(k_ff.rows(), 2);
  EXPECT_EQ(deferred->solve(rhs), SparseCholesky(k_ff).solve(rhs));
  const SparseCholesky direct(k_ff);
  EXPECT_EQ(&DeferredCholesky::borrowing(direct).factor(), &direct);
}

TEST(DeferredCholesky, AMatrixThatIsNotPositiveDefiniteFailsAtEveryUseNamingTheRow) {
  const TetMesh mesh = make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(1),
                                     Eigen::Vector3i::Constant(2));
  std::vector<AxisMask> fixed(static_cast<std::size_t>(mesh.node_count()), 0);
  fixed[0] = fixed[1] = fixed[3] = kAllAxes;
  const DofMap dofs = make_dof_map(fixed);
  const DeferredCholesky deferred(
      restrict_to_dofs(-assemble_stiffness(mesh, kSoft), dofs.free_dofs),  // negative definite
      [&](int row) { return "node " + std::to_string(mesh.node_tags[dofs.free_dofs[row] / 3]); });
  for (int attempt = 0; attempt < 2; ++attempt) {
    try {
      deferred.factor();
      FAIL() << "no error";
    } catch (const NumericalError& e) {
      EXPECT_NE(std::string(e.what()).find("first failure at node "), std::string::npos)
          << e.what();
    }
    EXPECT_FALSE(deferred.factored());
  }
  EXPECT_THROW(DeferredCholesky().factor(), Error);
}

TEST(PatchTest, ALinearFieldOnTheBoundaryIsReproducedInsideADistortedMesh) {
  const TetMesh mesh = testing::distorted_box_mesh(1.0, 4, 0.25, 7);
  for (int t = 0; t < mesh.tet_count(); ++t) ASSERT_GT(signed_volume(mesh, t), 0);
  const BoundarySurface surface = extract_boundary_surface(mesh);
  Eigen::Matrix3d gradient;
  gradient << 0.010, -0.004, 0.002, 0.003, -0.007, 0.001, -0.002, 0.005, 0.006;
  const Eigen::Vector3d offset(0.001, -0.002, 0.0005);
  const auto exact = [&](int node) -> Eigen::Vector3d {
    return offset + gradient * mesh.nodes.col(node);
  };

  const DofMap dofs =
      make_dof_map(std::vector<AxisMask>(static_cast<std::size_t>(mesh.node_count()), 0));
  std::vector<PrescribedDisplacement> prescribed;
  for (int node : surface.nodes)
    for (int a = 0; a < 3; ++a) prescribed.push_back({3 * node + a, exact(node)[a]});
  const StaticSolution solution =
      solve_static(assemble_stiffness(mesh, {2.0e4, 0.35}), dofs, prescribed);

  double worst = 0, scale = 0;
  std::vector<bool> on_surface(static_cast<std::size_t>(mesh.node_count()), false);
  for (int node : surface.nodes) on_surface[node] = true;
  int interior = 0;
  for (int node = 0; node < mesh.node_count(); ++node) {
    scale = std::max(scale, exact(node).norm());
    if (on_surface[node]) continue;
    ++interior;
    worst = std::max(worst, (solution.displacement.segment<3>(3 * node) - exact(node)).norm());
    // A linear field is in equilibrium without body forces: no force at interior nodes.
    EXPECT_LE(solution.reaction.segment<3>(3 * node).norm(), 1e-9);
  }
  EXPECT_EQ(interior, 27);
  EXPECT_LE(worst, 1e-10 * scale);
}

// A block with three sliding faces (symmetry planes) compressed on its top face: uniaxial
// stress, so the force is E A eps and the sides expand by nu eps, exactly for linear tets.
TEST(UniaxialCompression, ForceIsEAEpsilonWithSlidingFaces) {
  const std::string yaml = R"(
units: mm
objects:
  - name: block
    mesh: {box: {min: [0, 0, 0], size: [20, 30, 50], divisions: [3, 4, 6]}}
    material: {youngs_modulus: 2.5e4, poisson_ratio: 0.45}
    fixed:
      - {plane: {point: [0, 0, 0], normal: [0, 0, 1]}, axes: z}
      - {plane: {point: [0, 0, 0], normal: [1, 0, 0]}, axes: x}
      - {plane: {point: [0, 0, 0], normal: [0, 1, 0]}, axes: y}
tools: [{name: A}]
)";
  const Model model = build_model(parse_scene(yaml, "uniaxial.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  const double strain = 0.01, height = 0.05, area = 0.02 * 0.03, modulus = 2.5e4, nu = 0.45;
  std::vector<PrescribedDisplacement> prescribed;
  std::vector<int> top;
  for (int node = 0; node < body.mesh.node_count(); ++node)
    if (std::abs(body.mesh.nodes(2, node) - height) < 1e-12) {
      top.push_back(node);
      prescribed.push_back({3 * node + 2, -strain * height});
    }
  ASSERT_EQ(top.size(), 4u * 5u);
  const StaticSolution solution = solve_static(body.stiffness, body.dofs, prescribed);
  double force = 0;
  for (int node : top) force += solution.reaction[3 * node + 2];
  EXPECT_NEAR(force, -modulus * area * strain, 1e-8 * modulus * area * strain);
  for (int node = 0; node < body.mesh.node_count(); ++node) {
    const Eigen::Vector3d x = body.mesh.nodes.col(node);
    const Eigen::Vector3d expected(nu * strain * x.x(), nu * strain * x.y(), -strain * x.z());
    EXPECT_LE((solution.displacement.segment<3>(3 * node) - expected).norm(),
              1e-10 * strain * height);
  }
}

// Tip deflection of a clamped square beam under an end load, against Timoshenko beam
// theory. Linear tetrahedra lock in bending (and more so as nu -> 0.5): the error is large
// on coarse meshes and falls with refinement. The table is printed, not hidden.
double cantilever_tip_deflection(int along, double nu,
                                 ElementFormulation formulation = ElementFormulation::linear_tet) {
  const double length = 0.1, side = 0.01, load = 1e-3, modulus = 1e6;
  const int across = std::max(1, along / 10);
  const TetMesh mesh = make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d(length, side, side),
                                     Eigen::Vector3i(along, across, across));
  std::vector<AxisMask> fixed(static_cast<std::size_t>(mesh.node_count()), 0);
  for (int i = 0; i < mesh.node_count(); ++i)
    if (mesh.nodes(0, i) < 1e-12) fixed[i] = kAllAxes;
  // Uniform shear traction on the end face: consistent loads, a third of each triangle's share.
  const BoundarySurface surface = extract_boundary_surface(mesh);
  Eigen::VectorXd loads = Eigen::VectorXd::Zero(3 * mesh.node_count());
  for (const Triangle& tri : surface.triangles) {
    const Eigen::Vector3d a = mesh.nodes.col(tri[0]), b = mesh.nodes.col(tri[1]),
                          c = mesh.nodes.col(tri[2]);
    if (std::abs(a.x() - length) + std::abs(b.x() - length) + std::abs(c.x() - length) > 1e-12)
      continue;
    const double share = load * 0.5 * (b - a).cross(c - a).norm() / (side * side);
    for (int v : tri) loads[3 * v + 2] -= share / 3;
  }
  const StaticSolution solution = solve_static(assemble_stiffness(mesh, {modulus, nu, formulation}),
                                               make_dof_map(fixed), {}, loads);
  // The load-weighted deflection: P delta = work of the load = 2 x strain energy.
  return loads.dot(solution.displacement) / load;
}

double timoshenko_tip_deflection(double nu) {
  const double length = 0.1, side = 0.01, load = 1e-3, modulus = 1e6;
  const double inertia = side * side * side * side / 12, shear_modulus = modulus / (2 * (1 + nu));
  const double shear_coefficient = 10 * (1 + nu) / (12 + 11 * nu);  // rectangular section
  return load * length * length * length / (3 * modulus * inertia) +
         load * length / (shear_coefficient * shear_modulus * side * side);
}

TEST(Cantilever, TipDeflectionApproachesBeamTheoryAsTheMeshIsRefined) {
  const std::vector<int> refinements = {10, 20, 40, 80};
  const std::vector<double> ratios = {0.3, 0.45, 0.499};
  std::printf("\n  cantilever 100 x 10 x 10 mm, tip load: FE / Timoshenko tip deflection\n");
  std::printf("  %-14s", "divisions");
  for (double nu : ratios) std::printf("  nu = %-7g", nu);
  std::printf("\n");
  std::vector<std::vector<double>> error(ratios.size());
  for (int along : refinements) {
    std::printf("  %3d x %2d x %2d  ", along, std::max(1, along / 10), std::max(1, along / 10));
    for (std::size_t r = 0; r < ratios.size(); ++r) {
      const double ratio =
          cantilever_tip_deflection(along, ratios[r]) / timoshenko_tip_deflection(ratios[r]);
      error[r].push_back(std::abs(1 - ratio));
      std::printf("  %-12.4f", ratio);
    }
    std::printf("\n");
  }
  for (std::size_t r = 0; r < ratios.size(); ++r)
    for (std::size_t i = 1; i < refinements.size(); ++i)
      EXPECT_LT(error[r][i], error[r][i - 1])
          << "nu " << ratios[r] << " refinement " << refinements[i];
  EXPECT_LT(error[0].back(), 0.10);  // nu = 0.3, finest mesh: within 10 % of beam theory
  // Volumetric locking: near incompressibility the same mesh is much too stiff.
  EXPECT_GT(error[2].back(), 2 * error[0].back());
}

// Average-nodal-pressure tetrahedra remove the volumetric locking: at nu = 0.49 on the
// 30,720-tetrahedron beam plain tets give well under 90 % of beam theory, these at least 90 %.
TEST(NodalPressureTet, CantileverReachesBeamTheoryNearIncompressibilityWherePlainTetsLock) {
  const double nu = 0.49;
  const double beam = timoshenko_tip_deflection(nu);
  const double plain = cantilever_tip_deflection(80, nu) / beam;
  const double nodal =
      cantilever_tip_deflection(80, nu, ElementFormulation::nodal_pressure_tet) / beam;
  const double nodal_coarse =
      cantilever_tip_deflection(40, nu, ElementFormulation::nodal_pressure_tet) / beam;
  std::printf(
      "  nu = 0.49, FE / Timoshenko: plain 80x8x8 %.4f, nodal pressure 40x4x4 %.4f, 80x8x8 %.4f\n",
      plain, nodal_coarse, nodal);
  EXPECT_LT(plain, 0.7);
  EXPECT_GE(nodal, 0.90);
  EXPECT_LT(nodal, 1.05);
  EXPECT_LT(nodal_coarse, nodal) << "refinement still softens";
}

// The patch test: a linear displacement field imposed on the boundary of a distorted mesh
// is reproduced exactly inside (constant stress is represented exactly), for both
// formulations, also near incompressibility.
TEST(NodalPressureTet, PassesThePatchTest) {
  const TetMesh mesh = testing::distorted_box_mesh(0.05, 5, 0.25, 4);
  const BoundarySurface surface = extract_boundary_surface(mesh);
  std::vector<bool> on_boundary(static_cast<std::size_t>(mesh.node_count()), false);
  for (const Triangle& tri : surface.triangles)
    for (int v : tri) on_boundary[v] = true;
  Eigen::Matrix3d gradient;
  gradient << 0.010, -0.004, 0.002, 0.003, -0.006, 0.001, -0.002, 0.005, 0.008;
  const Eigen::Vector3d offset(1e-4, -2e-4, 3e-4);
  std::vector<PrescribedDisplacement> prescribed;
  for (int i = 0; i < mesh.node_count(); ++i)
    if (on_boundary[i]) {
      const Eigen::Vector3d u = gradient * mesh.nodes.col(i) + offset;
      for (int a = 0; a < 3; ++a) prescribed.push_back({3 * i + a, u[a]});
    }
  const DofMap dofs =
      make_dof_map(std::vector<AxisMask>(static_cast<std::size_t>(mesh.node_count()), 0));
  for (const auto formulation :
       {ElementFormulation::linear_tet, ElementFormulation::nodal_pressure_tet})
    for (const double nu : {0.3, 0.499}) {
      const StaticSolution solution =
          solve_static(assemble_stiffness(mesh, {1e5, nu, formulation}), dofs, prescribed);
      double worst = 0;
      int interior = 0;
      for (int i = 0; i < mesh.node_count(); ++i) {
        if (on_boundary[i]) continue;
        ++interior;
        const Eigen::Vector3d exact = gradient * mesh.nodes.col(i) + offset;
        worst = std::max(worst,
                         (solution.displacement.segment<3>(3 * i) - exact).norm() / exact.norm());
      }
      EXPECT_GT(interior, 20);
      EXPECT_LT(worst, 1e-9) << formulation_name(formulation) << " nu " << nu;
    }
}

// The assembled K against the energy computed node by node and element by element:
// u^T K u / 2 = sum_e V_e eps_e^T D_dev eps_e / 2 + kappa / 2 sum_a V_a theta_a^2; and K
// is symmetric with the rigid motions in its null space.
TEST(NodalPressureTet, StiffnessGivesTheNodalPressureEnergy) {
  const TetMesh mesh = testing::distorted_box_mesh(0.04, 3, 0.2, 7);
  const LinearElasticMaterial material{2e5, 0.45, ElementFormulation::nodal_pressure_tet};
  const SparseMatrix k = assemble_stiffness(mesh, material);
  EXPECT_LE((SparseMatrix(k.transpose()) - k).norm(), 1e-12 * k.norm());

  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(-1e-3, 1e-3);
  const Eigen::VectorXd u =
      Eigen::VectorXd::NullaryExpr(3 * mesh.node_count(), [&] { return uniform(rng); });
  const Eigen::Matrix<double, 6, 6> deviatoric = deviatoric_elasticity_matrix(material);
  std::vector<double> nodal_volume(static_cast<std::size_t>(mesh.node_count()), 0.0);
  std::vector<double> nodal_dilatation_volume(static_cast<std::size_t>(mesh.node_count()), 0.0);
  double energy = 0;
  for (const Tet& tet : mesh.tets) {
    Eigen::Matrix<double, 3, 4> corners;
    Eigen::Matrix<double, 12, 1> ue;
    for (int i = 0; i < 4; ++i) {
      corners.col(i) = mesh.nodes.col(tet[i]);
      ue.segment<3>(3 * i) = u.segment<3>(3 * tet[i]);
    }
    double volume = 0;
    const Eigen::Matrix<double, 6, 1> strain =
        tet_strain_matrix(tet_shape_gradients(corners, volume)) * ue;
    energy += 0.5 * volume * strain.dot(deviatoric * strain);
    for (int i = 0; i < 4; ++i) {
      nodal_volume[tet[i]] += volume / 4;
      nodal_dilatation_volume[tet[i]] += volume / 4 * strain.head<3>().sum();
    }
  }
  for (int a = 0; a < mesh.node_count(); ++a)
    energy += 0.5 * material.bulk_modulus() * nodal_dilatation_volume[a] *
              nodal_dilatation_volume[a] / nodal_volume[a];
  EXPECT_NEAR(0.5 * u.dot(k * u), energy, 1e-12 * energy);

  // Translations and infinitesimal rotations cost nothing.
  for (int mode = 0; mode < 6; ++mode) {
    Eigen::VectorXd rigid(3 * mesh.node_count());
    for (int i = 0; i < mesh.node_count(); ++i) {
      const Eigen::Vector3d axis = Eigen::Vector3d::Unit(mode % 3);
      rigid.segment<3>(3 * i) = mode < 3 ? axis : Eigen::Vector3d(axis.cross(mesh.nodes.col(i)));
    }
    EXPECT_LE((k * rigid).norm(), 1e-9 * k.norm() * rigid.norm()) << "mode " << mode;
  }
}

TEST(StaticSolve, AgreesWithTheIndependentFemUnderLoadsAndPrescribedDisplacements) {
  const TetMesh mesh = testing::distorted_box_mesh(0.08, 5, 0.2, 9);
  const double modulus = 3.0e5, nu = 0.45;
  std::vector<AxisMask> fixed_axes(static_cast<std::size_t>(mesh.node_count()), 0);
  std::vector<bool> fixed(static_cast<std::size_t>(3 * mesh.node_count()), false);
  for (int i = 0; i < mesh.node_count(); ++i)
    if (mesh.nodes(2, i) < 1e-12) {
      fixed_axes[i] = kAllAxes;
      fixed[3 * i] = fixed[3 * i + 1] = fixed[3 * i + 2] = true;
    }
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::vector<PrescribedDisplacement> prescribed;
  std::map<int, double> prescribed_map;
  Eigen::VectorXd loads = Eigen::VectorXd::Zero(3 * mesh.node_count());
  for (int i = 0; i < mesh.node_count(); ++i) {
    if (std::abs(mesh.nodes(2, i) - 0.08) < 1e-12 && std::abs(mesh.nodes(0, i) - 0.04) < 0.02) {
      for (int a = 0; a < 3; ++a) {
        prescribed.push_back({3 * i + a, 1e-3 * uniform(rng)});
        prescribed_map[3 * i + a] = prescribed.back().value;
      }
    } else if (std::abs(mesh.nodes(0, i)) < 1e-12) {
      loads.segment<3>(3 * i) = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
    }
  }
  ASSERT_FALSE(prescribed.empty());
  const StaticSolution solution = solve_static(assemble_stiffness(mesh, {modulus, nu}),
                                               make_dof_map(fixed_axes), prescribed, loads);
  const testing::IndependentSolution expected =
      testing::independent_static_solve(mesh, modulus, nu, fixed, prescribed_map, loads);
  EXPECT_LE((solution.displacement - expected.displacement).norm(),
            1e-9 * expected.displacement.norm());
  EXPECT_LE((solution.reaction - expected.reaction).norm(), 1e-8 * expected.reaction.norm());
  // Equilibrium: all reactions together balance the applied loads.
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (int i = 0; i < mesh.node_count(); ++i)
    total += solution.reaction.segment<3>(3 * i) + loads.segment<3>(3 * i);
  EXPECT_LE(total.norm(), 1e-9 * loads.norm());
}

TEST(StaticSolve, RejectsPrescribingAFixedOrRepeatedDof) {
  const TetMesh mesh = make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(1),
                                     Eigen::Vector3i::Constant(1));
  std::vector<AxisMask> fixed(static_cast<std::size_t>(mesh.node_count()), 0);
  fixed[0] = kAllAxes;
  const DofMap dofs = make_dof_map(fixed);
  const SparseMatrix k = assemble_stiffness(mesh, kSoft);
  EXPECT_THROW(solve_static(k, dofs, {{1, 0.1}}), Error);
  EXPECT_THROW(solve_static(k, dofs, {{4, 0.1}, {4, 0.2}}), Error);
}

}  // namespace
}  // namespace cohaptic
