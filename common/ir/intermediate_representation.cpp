#include "common/ir/intermediate_representation.h"

namespace cohaptic {

std::size_t IntermediateRepresentation::size_bytes() const {
  const std::size_t scalar = precision == IrPrecision::f32 ? sizeof(float) : sizeof(double);
  constexpr std::size_t kHeader = 4 + 8 + 8 + 4 + 1 + 1 + 8 + 8 + 4 + 4;  // version .. row_node_count
  const std::size_t nodes = node_ids.size() * (sizeof(std::int64_t) + sizeof(AxisMask)) +
                            static_cast<std::size_t>(rest_positions.size()) * sizeof(double);
  const std::size_t triangles = patch.size() * (7 * sizeof(std::int32_t) + 4 * 3 * sizeof(double)) +
                               static_cast<std::size_t>(patch_vertex_normals.size()) * sizeof(double) +
                               guard.size() * 4 * 3 * sizeof(double);
  const std::size_t remote = remotes.size() * (sizeof(std::int32_t) * 4 + (1 + 7 * 3) * sizeof(double));
  const std::size_t matrix = static_cast<std::size_t>(m_tilde.size() + boundary_displacement.size()) * scalar;
  return kHeader + nodes + triangles + remote + matrix;
}

std::vector<int> ir_dofs(const IntermediateRepresentation& ir, int first_node, int last_node) {
  std::vector<int> dofs;
  for (int node = first_node; node < last_node; ++node)
    for (int axis = 0; axis < 3; ++axis)
      if (!((ir.fixed_axes[node] >> axis) & 1u)) dofs.push_back(3 * node + axis);
  return dofs;
}

}  // namespace cohaptic
