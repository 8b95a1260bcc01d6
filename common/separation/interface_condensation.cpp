#include "common/separation/interface_condensation.h"

#include <Eigen/Cholesky>
#include <chrono>
#include <fmt/format.h>

#include "common/fem/assemble_stiffness.h"
#include "common/fem/compliance.h"
#include "common/fem/sparse_cholesky.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

Eigen::MatrixXd body_interface_compliance(const SeparationBody& body, const std::vector<int>& nodes,
                                          const char* name) {
  const DofMap dofs = make_dof_map(body.fixed_axes);
  const SparseMatrix k_ff =
      restrict_to_dofs(assemble_stiffness(body.mesh, body.material), dofs.free_dofs);
  try {
    const SparseCholesky factor(k_ff, [&](int row) {
      const int dof = dofs.free_dofs[row];
      return fmt::format("node {} axis {}", body.mesh.node_tags[dof / 3], "xyz"[dof % 3]);
    });
    ComplianceColumns columns(factor, dofs, nodes);
    return columns.gather(nodes);
  } catch (const NumericalError& e) {
    throw NumericalError(
        fmt::format("separation: the {} body's stiffness is singular ({}); its supports must leave "
                    "it no rigid motion on its own",
                    name, e.what()));
  }
}

std::vector<int> dofs_of(std::span<const int> nodes) {
  std::vector<int> dofs;
  dofs.reserve(3 * nodes.size());
  for (int node : nodes)
    for (int axis = 0; axis < 3; ++axis) dofs.push_back(3 * node + axis);
  return dofs;
}

Eigen::MatrixXd rows_of(const Eigen::MatrixXd& m, const std::vector<int>& rows) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(rows.size()), m.cols());
  for (std::size_t i = 0; i < rows.size(); ++i)
    out.row(static_cast<Eigen::Index>(i)) = m.row(rows[i]);
  return out;
}

Eigen::MatrixXd block_of(const Eigen::MatrixXd& m, const std::vector<int>& rows,
                         const std::vector<int>& cols) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(rows.size()),
                      static_cast<Eigen::Index>(cols.size()));
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < cols.size(); ++j)
      out(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = m(rows[i], cols[j]);
  return out;
}

}  // namespace

InterfaceCompliance interface_compliance(const SeparationBodies& bodies,
                                         const SeparationInterface& interface) {
  for (int k = 0; k < interface.node_count(); ++k)
    if (bodies.pulled.fixed_axes[interface.pulled_nodes[k]] != 0)
      throw Error(fmt::format(
          "separation: interface node {} of the pulled body is supported; the force fields need "
          "every interface node of the pulled body free",
          bodies.pulled.mesh.node_tags[interface.pulled_nodes[k]]));
  const auto start = std::chrono::steady_clock::now();
  InterfaceCompliance compliance;
  compliance.pulled = body_interface_compliance(bodies.pulled, interface.pulled_nodes, "pulled");
  compliance.base = body_interface_compliance(bodies.base, interface.base_nodes, "base");
  compliance.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return compliance;
}

TiedInterface::TiedInterface(const InterfaceCompliance& compliance) : l1_(compliance.pulled) {
  // L1 is positive definite on the free interface nodes and L2 semi-definite: G is SPD.
  const Eigen::MatrixXd g = compliance.pulled + compliance.base;
  const Eigen::LLT<Eigen::MatrixXd> llt(g);
  if (llt.info() != Eigen::Success)
    throw NumericalError("separation: L1 + L2 on the interface is not positive definite");
  h_ = llt.solve(Eigen::MatrixXd::Identity(g.rows(), g.cols()));
  h_ = 0.5 * (h_ + h_.transpose()).eval();
  h_l1_ = h_ * l1_;
}

TiedInterface::FootprintCompliances TiedInterface::footprint_compliances(
    std::span<const int> footprint, std::span<const int> released) const {
  const std::vector<int> f = dofs_of(footprint);
  const std::vector<int> r = dofs_of(released);
  Eigen::MatrixXd v(l1_.rows(), static_cast<Eigen::Index>(f.size()));  // V = L1_:F
  Eigen::MatrixXd w(l1_.rows(), static_cast<Eigen::Index>(f.size()));  // W = H V
  for (std::size_t j = 0; j < f.size(); ++j) {
    v.col(static_cast<Eigen::Index>(j)) = l1_.col(f[j]);
    w.col(static_cast<Eigen::Index>(j)) = h_l1_.col(f[j]);
  }
  const Eigen::MatrixXd tied = v.transpose() * w;  // V^T G^-1 V with every pair tied
  // V_T^T (H_TT - H_TR H_RR^-1 H_RT) V_T written with W = H V (see the header).
  const Eigen::MatrixXd v_r = rows_of(v, r);
  const Eigen::MatrixXd w_r = rows_of(w, r);
  const Eigen::MatrixXd h_rr = block_of(h_, r, r);
  const Eigen::MatrixXd z = w_r - h_rr * v_r;
  const Eigen::MatrixXd released_tied =
      r.empty() ? tied
                : Eigen::MatrixXd(tied - v_r.transpose() * w_r - z.transpose() * v_r -
                                  z.transpose() * h_rr.ldlt().solve(z));
  const auto symmetric = [](const Eigen::MatrixXd& m) {
    return Eigen::MatrixXd(0.5 * (m + m.transpose()));
  };
  FootprintCompliances c;
  c.separated = block_of(l1_, f, f);
  c.connected = symmetric(c.separated - tied);
  c.locally_separated = symmetric(c.separated - released_tied);
  return c;
}

Eigen::Matrix3d rigid_footprint_stiffness(const Eigen::MatrixXd& footprint_compliance) {
  const Eigen::Index count = footprint_compliance.rows() / 3;
  Eigen::MatrixXd e(footprint_compliance.rows(), 3);
  for (Eigen::Index i = 0; i < count; ++i) e.middleRows<3>(3 * i).setIdentity();
  const Eigen::LLT<Eigen::MatrixXd> llt(footprint_compliance);
  if (llt.info() != Eigen::Success)
    throw NumericalError("separation: a footprint's compliance is not positive definite");
  const Eigen::Matrix3d k = e.transpose() * llt.solve(e);
  return 0.5 * (k + k.transpose());
}

}  // namespace cohaptic
