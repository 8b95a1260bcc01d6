// Assembly of the global stiffness matrix of a linear elastic tetrahedral mesh, in the
// material's element formulation (plain linear or average-nodal-pressure tetrahedra).
//
// K is 3N x 3N, symmetric, in N/m; before any dof is fixed its null space holds the six
// rigid-body modes. restrict_to_free_dofs gives K_ff, positive definite when the fixed
// dofs remove every rigid motion of every connected part.
#pragma once

#include <Eigen/SparseCore>

#include "common/fem/dof_map.h"
#include "common/fem/linear_elastic_material.h"
#include "common/mesh/tet_mesh.h"

namespace cohaptic {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

SparseMatrix assemble_stiffness(const TetMesh& mesh, const LinearElasticMaterial& material);

/// The rows and columns of `k` selected by `dofs` (K_ff for dofs = the free dofs).
SparseMatrix restrict_to_dofs(const SparseMatrix& k, const std::vector<int>& dofs);

}  // namespace cohaptic
