// The behind body's answer to a forcible displacement when it is a condensed linear FEM
// body (the several-objects paper, Sec. 2.4, Eqs. 8-9): with only the displaced nodes c
// prescribed and every other free node unloaded,
//   reaction    f_c = L_cc^-1 u_c   (the forces that hold the displaced nodes there)
//   deformation u_o = L_oc f_c      (every other surface node)
// where L = K_ff^-1 is the body's compliance, read from its ComplianceColumns (whose row
// nodes are the surface nodes that can collide). The displaced nodes are what the IR
// calls colliding boundary nodes B: prescribed, not pressed by a tool.
// Over free dofs only: a fixed axis of a displaced node gets no force here (its support
// carries it) and its displacement must be zero. Units: m, N, N/m.
// The workspace grows to the largest set seen, then a step allocates nothing (provided
// the columns of the displaced nodes were computed before).
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/fem/compliance.h"
#include "common/fem/dof_map.h"

namespace cohaptic {

struct CondensedResponseWorkspace {
  Eigen::MatrixXd compliance;  ///< L_cc, then its Cholesky factor, in the top-left corner
  Eigen::VectorXd values;      ///< free-dof values
  std::vector<int> free_dofs;  ///< position among the 3|nodes| of each free dof
};

/// f_c for displacements `displacement` (3 per node of `nodes`, node order) [N]: written to
/// `forces` (3 per node; zero on fixed axes). Throws NumericalError when L_cc is not
/// positive definite (a node listed twice).
void condensed_reaction(ComplianceColumns& columns, const DofMap& dofs, std::span<const int> nodes,
                        const Eigen::Ref<const Eigen::VectorXd>& displacement,
                        Eigen::Ref<Eigen::VectorXd> forces, CondensedResponseWorkspace& workspace);

/// u of every row node of `columns` (3 per row node, row order) under forces `forces` at
/// `nodes` (3 per node) [m], written to `row_displacement` (sized 3 |columns.row_nodes()|).
void condensed_deformation(ComplianceColumns& columns, std::span<const int> nodes,
                           const Eigen::Ref<const Eigen::VectorXd>& forces,
                           Eigen::Ref<Eigen::VectorXd> row_displacement);

/// L_cc^-1 over the 3|nodes| dofs of `nodes` (zero rows and columns on fixed axes): the
/// behind body's stiffness condensed onto its displaced nodes [N/m].
Eigen::MatrixXd condensed_stiffness(ComplianceColumns& columns, const DofMap& dofs,
                                    std::span<const int> nodes);

}  // namespace cohaptic
