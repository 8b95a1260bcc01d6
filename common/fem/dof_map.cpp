#include "common/fem/dof_map.h"

namespace cohaptic {

DofMap make_dof_map(std::vector<AxisMask> fixed_axes) {
  DofMap map;
  map.fixed_axes = std::move(fixed_axes);
  map.free_index.assign(3 * map.fixed_axes.size(), -1);
  for (int node = 0; node < map.node_count(); ++node)
    for (int axis = 0; axis < 3; ++axis)
      if (!map.is_fixed(node, axis)) {
        map.free_index[3 * node + axis] = map.free_count();
        map.free_dofs.push_back(3 * node + axis);
      }
  return map;
}

}  // namespace cohaptic
