#include "common/ir/intermediate_representation.h"

#include <fmt/format.h>

#include <limits>

#include "common/util/error.h"
#include "common/util/overloaded.h"
#include "common/util/visit_held.h"

namespace cohaptic {

std::size_t IntermediateRepresentation::size_bytes() const {
  constexpr std::size_t kEnvelope = 4 + 8 + 8 + 4 + 4 + 8 + 8;  // version .. force_limit
  return kEnvelope + std::visit([](const auto& content) { return content.size_bytes(); }, body);
}

std::size_t CondensedFemIr::size_bytes() const {
  const std::size_t scalar = precision == IrPrecision::f32 ? sizeof(float) : sizeof(double);
  constexpr std::size_t kHeader =
      1 + 1 + 4 + 4;  // contact model, precision, patch and row node counts
  const std::size_t nodes = node_ids.size() * (sizeof(std::int64_t) + sizeof(AxisMask)) +
                            static_cast<std::size_t>(rest_positions.size()) * sizeof(double);
  const std::size_t triangles =
      patch.size() * (7 * sizeof(std::int32_t) + 4 * 3 * sizeof(double)) +
      static_cast<std::size_t>(patch_vertex_normals.size()) * sizeof(double) +
      guard.size() * 4 * 3 * sizeof(double);
  const std::size_t remote =
      remotes.size() * (sizeof(std::int32_t) * 4 + (1 + 7 * 3) * sizeof(double));
  const std::size_t matrix =
      static_cast<std::size_t>(m_tilde.size() + boundary_displacement.size()) * scalar +
      static_cast<std::size_t>(rest_forces.size()) * sizeof(double) +
      (compliance_rows ? 8 + static_cast<std::size_t>(compliance_rows->rows.size()) * sizeof(double)
                       : 0);
  const std::size_t truncated =  // sent with compliance rows only
      compliance_rows ? truncated_node_ids.size() * (sizeof(std::int64_t) + sizeof(AxisMask)) : 0;
  std::size_t sphere_bytes = 0;
  if (sphere) {  // W as its upper triangle, at the stored precision (f64 as rows)
    const auto n = static_cast<std::size_t>(sphere->normal_compliance.rows());
    sphere_bytes =
        static_cast<std::size_t>(sphere->normals.size() + sphere->free_clearance.size()) *
            sizeof(double) +
        n * (n + 1) / 2 * scalar + sphere->contacts.size() * sizeof(std::int32_t) +
        sphere->held_node_ids.size() * sizeof(std::int64_t) +
        static_cast<std::size_t>(
            (sphere->obstacle_gaps.array() < std::numeric_limits<double>::infinity()).count()) *
            (sizeof(std::uint32_t) + sizeof(double));
  }
  return kHeader + nodes + triangles + remote + matrix + truncated + sphere_bytes;
}

std::vector<std::int64_t> CondensedFemIr::held_node_ids() const {
  std::vector<std::int64_t> held = node_ids;
  held.insert(held.end(), truncated_node_ids.begin(), truncated_node_ids.end());
  return held;
}

const CondensedFemIr& condensed_fem(const IntermediateRepresentation& ir) {
  if (const auto* fem = std::get_if<CondensedFemIr>(&ir.body)) return *fem;
  throw Error(
      fmt::format("the IR of user {} (epoch {}) is not a condensed FEM body", ir.user, ir.epoch));
}

CondensedFemIr& condensed_fem(IntermediateRepresentation& ir) {
  return const_cast<CondensedFemIr&>(
      condensed_fem(static_cast<const IntermediateRepresentation&>(ir)));
}

std::size_t MassSpringIr::size_bytes() const {
  constexpr std::size_t kParameters =
      (3 + 3 + 3 + 3 + 2) * sizeof(double) + 1;  // gravity .. time step, plane
  const std::size_t nodes = node_ids.size() * (sizeof(std::int32_t) + 7 * sizeof(double) + 1);
  const std::size_t springs_bytes =
      springs.size() * (2 * sizeof(std::int32_t) + 3 * sizeof(double));
  const std::size_t tools = remote_users.size() * (sizeof(std::int32_t) + sizeof(double)) +
                            presses.size() * (1 + 3 * sizeof(double));
  const std::size_t backed = backing.nodes.size();
  const std::size_t backing_bytes =
      backed * (sizeof(std::int32_t) + 8 * sizeof(double)) + backed * backed * sizeof(double);
  return kParameters + nodes + springs_bytes + triangles.size() * 3 * sizeof(std::int32_t) + tools +
         backing_bytes;
}

int remote_count(const IntermediateRepresentation& ir) noexcept {
  return visit_held(
      ir.body,
      Overloaded{
          [](const CondensedFemIr& fem) { return static_cast<int>(fem.remotes.size()); },
          [](const MassSpringIr& network) { return static_cast<int>(network.remote_users.size()); },
          [](const HomeSpringPatch&) { return 0; }, [](const SeparationIr&) { return 0; }},
      0);
}

int remote_user(const IntermediateRepresentation& ir, int i) noexcept {
  const auto at = static_cast<std::size_t>(i);
  return visit_held(
      ir.body,
      Overloaded{[at](const CondensedFemIr& fem) { return fem.remotes[at].user; },
                 [at](const MassSpringIr& network) { return network.remote_users[at]; },
                 [](const HomeSpringPatch&) { return -1; }, [](const SeparationIr&) { return -1; }},
      -1);
}

std::vector<int> ir_dofs(const CondensedFemIr& ir, int first_node, int last_node) {
  std::vector<int> dofs;
  for (int node = first_node; node < last_node; ++node)
    for (int axis = 0; axis < 3; ++axis)
      if (!((ir.fixed_axes[node] >> axis) & 1u)) dofs.push_back(3 * node + axis);
  return dofs;
}

}  // namespace cohaptic
