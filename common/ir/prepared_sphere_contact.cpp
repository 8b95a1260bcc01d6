#include "common/ir/prepared_sphere_contact.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/condense/naive_condensation.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

// How far from 1 a normal's length may be.
constexpr double kUnitTolerance = 1e-9;

}  // namespace

PreparedSphereContact prepare_sphere_contact(const CondensedFemIr& ir, double tool_radius,
                                             double& condition_estimate) {
  if (!ir.sphere)
    throw Error(
        "intermediate representation: the sphere contact model without its normal compliance");
  if (ir.compliance_rows)
    throw Error(
        "intermediate representation: a sphere body carries its normal compliance, never "
        "compliance rows");
  const SphereContactIr& sphere = *ir.sphere;
  const auto n = static_cast<Eigen::Index>(ir.row_node_count);
  if (ir.node_count() != n || ir.m_tilde.size() != 0 || ir.boundary_displacement.size() != 0 ||
      ir.rest_forces.size() != 0)
    throw Error(
        "intermediate representation: a sphere body carries its row nodes and W only (no held "
        "nodes, M~ or u_B)");
  if (sphere.normals.cols() != n || sphere.free_clearance.size() != n ||
      sphere.normal_compliance.rows() != n || sphere.normal_compliance.cols() != n)
    throw Error(
        fmt::format("intermediate representation: {} normals, {} free clearances and a {}x{} W for "
                    "{} row nodes",
                    sphere.normals.cols(), sphere.free_clearance.size(),
                    sphere.normal_compliance.rows(), sphere.normal_compliance.cols(), n));
  if (!sphere.normals.allFinite() || !sphere.free_clearance.allFinite() ||
      !sphere.normal_compliance.allFinite())
    throw Error(
        "intermediate representation: non-finite values in the sphere contact's normals, "
        "clearances or W");
  if (sphere.obstacle_gaps.size() != 0 && sphere.obstacle_gaps.size() != n)
    throw Error(fmt::format("intermediate representation: {} obstacle gaps for {} row nodes",
                            sphere.obstacle_gaps.size(), n));
  for (Eigen::Index i = 0; i < sphere.obstacle_gaps.size(); ++i)
    if (const double gap = sphere.obstacle_gaps[i];
        gap != std::numeric_limits<double>::infinity() &&
        (!std::isfinite(gap) || sphere.normals.col(i).squaredNorm() == 0))
      throw Error(fmt::format("intermediate representation: row node {}'s obstacle gap is {}{}", i,
                              gap, std::isfinite(gap) ? " but it has no normal" : ""));
  if (!(tool_radius > 0))
    throw Error("intermediate representation: the sphere model needs a sphere tool (radius > 0)");
  for (const IrRemoteContact& remote : ir.remotes)
    if (!(remote.tool_radius > 0))
      throw Error(
          fmt::format("intermediate representation: the sphere model needs a sphere tool, and user "
                      "{}'s has radius {}",
                      remote.user, remote.tool_radius));
  const Eigen::MatrixXd& w = sphere.normal_compliance;
  const double scale = n > 0 ? w.cwiseAbs().maxCoeff() : 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double length = sphere.normals.col(i).norm();
    if (length != 0 && std::abs(length - 1) > kUnitTolerance)
      throw Error(fmt::format("intermediate representation: row node {}'s normal has length {}", i,
                              length));
    if (length != 0 && !(w(i, i) > 0))
      throw Error(fmt::format(
          "intermediate representation: W's diagonal at row node {} is {}, not positive", i,
          w(i, i)));
    for (Eigen::Index j = 0; j < i; ++j)
      if (std::abs(w(i, j) - w(j, i)) > kMaxRelativeAsymmetry * scale)
        throw Error(fmt::format(
            "intermediate representation: W is not symmetric at ({}, {}): {:g} against {:g}", i, j,
            w(i, j), w(j, i)));
  }

  PreparedSphereContact prepared;
  prepared.nonnegative_rows.assign(static_cast<std::size_t>(n), 1);
  for (Eigen::Index i = 0; i < n; ++i)
    prepared.nonnegative_rows[static_cast<std::size_t>(i)] = w.row(i).minCoeff() >= 0;
  prepared.start = IncrementalContactSolve(static_cast<int>(n));
  int previous = -1;
  for (int node : sphere.contacts) {
    if (node <= previous || node >= n || sphere.normals.col(node).squaredNorm() == 0)
      throw Error(fmt::format(
          "intermediate representation: contact {} is not a row node the sphere model can hold, in "
          "ascending order",
          node));
    previous = node;
  }
  if (!prepared.start.start_from(w, sphere.contacts))
    throw Error(
        fmt::format("intermediate representation: W over the {} contacts is not positive definite",
                    sphere.contacts.size()));
  condition_estimate =
      sphere.contacts.empty() ? 1.0 : cholesky_condition_estimate(prepared.start.factor());

  std::vector<Eigen::Vector3d> outside;
  for (const IrGuardTriangle& guard : ir.guard)
    for (const Eigen::Vector3d& corner : guard.corners) {
      bool row_node = false;
      for (Eigen::Index i = 0; i < n && !row_node; ++i)
        row_node = ir.rest_positions.col(i) == corner;
      bool listed = false;
      for (const Eigen::Vector3d& seen : outside) listed |= seen == corner;
      if (!row_node && !listed) outside.push_back(corner);
    }
  prepared.outside_corners.resize(3, static_cast<Eigen::Index>(outside.size()));
  for (std::size_t i = 0; i < outside.size(); ++i)
    prepared.outside_corners.col(static_cast<Eigen::Index>(i)) = outside[i];
  return prepared;
}

SphereContactState make_sphere_contact_state(const PreparedSphereContact& prepared, int row_nodes) {
  SphereContactState state;
  state.solve = prepared.start;
  state.clearance = Eigen::VectorXd::Constant(row_nodes, std::numeric_limits<double>::infinity());
  state.holder.assign(static_cast<std::size_t>(row_nodes), -1);
  return state;
}

}  // namespace cohaptic
