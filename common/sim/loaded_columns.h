// LoadedColumns: a solved state's nodal forces (the pressing tools', the held nodes' and any
// applied loads), each with the column of the compliance L it acts through. That is all the
// displacement of every row node needs, u = sum_j L[rows, j] f_j, without the
// ComplianceColumns object: a snapshot the simulation thread takes in microseconds and
// another thread (the live view's) turns into a surface's displacement.
//
// Thread safety: a column, once cached by ComplianceColumns, is never changed or moved (its
// map keeps elements in place as it grows), so the pointers stay valid and their numbers
// fixed while the simulation thread adds other columns; they live as long as the
// ComplianceColumns. Units: force N, compliance m/N, displacement m.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/fem/compliance.h"
#include "common/sim/state_solve.h"

namespace cohaptic {

struct LoadedColumn {
  const ComplianceColumn* column = nullptr;  ///< L[row nodes, node], 3 columns (x, y, z)
  int axis = 0;                              ///< the column of it the force acts along
  double force = 0;                          ///< [N]
};

/// The loads of `state` (a solve over `columns`), computing any column not cached yet.
std::vector<LoadedColumn> loaded_columns(ComplianceColumns& columns, const StateSolution& state);

/// The displacement [m] of the row nodes at `row_positions` (ComplianceColumns::row_position)
/// under `loads`, one column each.
Eigen::Matrix3Xd displacement_of_rows(std::span<const LoadedColumn> loads,
                                      std::span<const int> row_positions);

}  // namespace cohaptic
