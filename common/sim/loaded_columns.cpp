#include "common/sim/loaded_columns.h"

#include <fmt/format.h>

#include "common/condense/dof_blocks.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

void add_loads(ComplianceColumns& columns, const std::vector<int>& dofs,
               const Eigen::VectorXd& forces, std::vector<LoadedColumn>& loads) {
  columns.compute_columns(nodes_of_dofs(dofs));  // one solve per group for any missing
  for (std::size_t j = 0; j < dofs.size(); ++j)
    loads.push_back(
        {&columns.column(dofs[j] / 3), dofs[j] % 3, forces[static_cast<Eigen::Index>(j)]});
}

}  // namespace

std::vector<LoadedColumn> loaded_columns(ComplianceColumns& columns, const StateSolution& state) {
  std::vector<LoadedColumn> loads;
  loads.reserve(state.contact_dofs.size() + state.boundary_dofs.size() + state.applied.dofs.size());
  add_loads(columns, state.contact_dofs, state.contact_forces, loads);
  add_loads(columns, state.boundary_dofs, state.boundary_forces, loads);
  add_loads(columns, state.applied.dofs, state.applied.forces, loads);
  return loads;
}

Eigen::Matrix3Xd displacement_of_rows(std::span<const LoadedColumn> loads,
                                      std::span<const int> row_positions) {
  Eigen::Matrix3Xd u = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(row_positions.size()));
  if (loads.empty()) return u;
  const Eigen::Index rows = loads.front().column->rows() / 3;  // every column has the same rows
  for (const int position : row_positions)
    if (position < 0 || position >= rows)
      throw Error(fmt::format("displacement_of_rows: row position {} outside the {} row nodes",
                              position, rows));
  for (const LoadedColumn& load : loads) {
    const auto along = load.column->col(load.axis);
    for (std::size_t k = 0; k < row_positions.size(); ++k)
      u.col(static_cast<Eigen::Index>(k)) +=
          load.force * along.segment<3>(3 * static_cast<Eigen::Index>(row_positions[k]));
  }
  return u;
}

}  // namespace cohaptic
