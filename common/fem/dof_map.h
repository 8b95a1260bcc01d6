// DofMap: which of the 3N nodal displacement components are free and how they are numbered.
//
// Global dof of node n, axis a (0 x, 1 y, 2 z) is 3n + a. A fixed dof has zero
// displacement (per-axis fixing expresses sliding boundaries). Free dofs are numbered
// 0..free_count()-1 in increasing global order; K_ff is the stiffness restricted to them.
#pragma once

#include <cstdint>
#include <vector>

namespace cohaptic {

/// Bit a of a node's mask set = axis a fixed.
using AxisMask = std::uint8_t;
constexpr AxisMask kAllAxes = 0b111;

struct DofMap {
  std::vector<AxisMask> fixed_axes;  ///< per node
  std::vector<int> free_index;       ///< per global dof: index among free dofs, or -1 if fixed
  std::vector<int> free_dofs;        ///< per free index: the global dof

  int node_count() const { return static_cast<int>(fixed_axes.size()); }
  int free_count() const { return static_cast<int>(free_dofs.size()); }
  bool is_fixed(int node, int axis) const {
    return (fixed_axes[static_cast<std::size_t>(node)] >> axis) & 1u;
  }
};

DofMap make_dof_map(std::vector<AxisMask> fixed_axes);

}  // namespace cohaptic
