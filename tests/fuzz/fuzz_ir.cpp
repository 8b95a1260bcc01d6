// Fuzz target: an intermediate representation from the wire, on the client's path: the
// conversion (proto/wire/ir_convert.h), prepare_ir() (common/ir/evaluate_force.h) and the
// haptic force evaluation. Seeded with real IRs, so the mutations are IRs that decode but
// lie: sizes, indices, NaN and infinities, asymmetric or indefinite M~, huge values.
//
// Input: a serialized wire::IntermediateRepresentation. Properties:
//   - from_wire(), a fresh client's completion of an IR sent as compliance rows
//     (ClientCondensation: rows of generation 1, any other refused) and prepare_ir() either
//     accept or throw cohaptic::Error; an M_CC accepted is symmetric to 1e-9 of its
//     largest entry;
//   - for an IR they accept, evaluate_force() returns a finite force no larger than the IR's
//     force limit, zero whenever it flags a non-finite value (what the haptic thread writes
//     to the motor), at probe positions by body kind:
//       condensed FEM: around every patch triangle and node (outside, on the surface,
//       pressed in by up to the patch's size), with the remote tools pressed into their
//       triangles;
//       mass-spring: a tool moving through the sub-network's nodes, one haptic tick
//       (1 ms) per position, the sub-network integrated all the while.
//       home-spring: a tool on the shaft through each touchable vertex from the trocar
//       pivot, short of it, on it and past it (and pulled aside while grasping);
//       separation: a tool at each triangle's centroid with its jaws closed (buttons 0
//       and 1: either kind of instrument), pulled away from the interface and along it,
//       then firing the laser across the patch, one haptic tick per position.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <variant>
#include <vector>

#include "common/ir/client_condensation.h"
#include "common/ir/evaluate_force.h"
#include "common/util/error.h"
#include "proto/wire/ir_convert.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using namespace cohaptic;
using fuzz::require;

constexpr double kHapticPeriod = 1e-3;  // [s]

void require_safe(const PreparedIR& prepared, EvaluationState& state, const Eigen::Vector3d& own,
                  std::span<const Eigen::Vector3d> remotes, std::uint32_t buttons = 0) {
  const ForceSample sample = evaluate_force(prepared, state, own, remotes, kHapticPeriod, buttons);
  require(sample.force.allFinite(), "the haptic force is finite");
  require(sample.force.norm() <= prepared.ir.force_limit * (1 + 1e-12),
          "the haptic force respects the IR's limit");
  require(!(sample.flags & kNonFinite) || sample.force.isZero(0),
          "a non-finite evaluation gives zero force");
}

// A point pressed `depth` below `point` along the outward `normal` (depth < 0: outside).
Eigen::Vector3d pressed(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, double depth) {
  return point - depth * normal;
}

void probe(const PreparedIR& prepared, const CondensedFemIr& ir) {
  const auto m_cc = ir.m_tilde.leftCols(ir.m_tilde.rows());
  if (m_cc.size() > 0)
    require((m_cc - m_cc.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * m_cc.cwiseAbs().maxCoeff(),
            "an accepted M_CC is symmetric");
  EvaluationState state = make_evaluation_state(prepared);

  // The patch's size sets the probe depths.
  const Eigen::Vector3d low = ir.rest_positions.rowwise().minCoeff(),
                        high = ir.rest_positions.rowwise().maxCoeff();
  const double extent = std::max((high - low).norm(), 1e-6);
  const std::array<double, 4> depths{-0.1 * extent, 0.0, 0.01 * extent, extent};

  // Remote tools pressed into the middle of their triangles.
  std::vector<Eigen::Vector3d> remotes;
  for (const IrRemoteContact& remote : ir.remotes) {
    const Eigen::Vector3d centre =
        (ir.rest_positions.col(remote.nodes[0]) + ir.rest_positions.col(remote.nodes[1]) +
         ir.rest_positions.col(remote.nodes[2])) /
        3;
    remotes.push_back(pressed(centre, remote.normal, 0.01 * extent));
  }

  constexpr std::size_t kMaxProbedTriangles = 16;
  for (std::size_t t = 0; t < std::min(ir.patch.size(), kMaxProbedTriangles); ++t) {
    const IrTriangle& triangle = ir.patch[t];
    const Eigen::Vector3d centre =
        (ir.rest_positions.col(triangle.nodes[0]) + ir.rest_positions.col(triangle.nodes[1]) +
         ir.rest_positions.col(triangle.nodes[2])) /
        3;
    for (double depth : depths) {
      require_safe(prepared, state, pressed(centre, triangle.normal, depth), remotes);
      require_safe(prepared, state,
                   pressed(ir.rest_positions.col(triangle.nodes[t % 3]), triangle.normal, depth),
                   {});
    }
  }
}

void probe(const PreparedIR& prepared, const MassSpringIr& ir) {
  EvaluationState state = make_evaluation_state(prepared);
  // The remote tools rest on the first nodes; the own tool visits nodes in turn and pauses
  // on each for a few ticks, so the sub-network reacts.
  std::vector<Eigen::Vector3d> remotes;
  for (std::size_t i = 0; i < ir.remote_users.size(); ++i)
    remotes.push_back(ir.node_count() > 0
                          ? Eigen::Vector3d(ir.positions.col(static_cast<int>(i) % ir.node_count()))
                          : Eigen::Vector3d::Zero());
  constexpr int kMaxProbedNodes = 16, kTicksPerNode = 4;
  for (int node = 0; node < std::min(ir.node_count(), kMaxProbedNodes); ++node)
    for (int tick = 0; tick < kTicksPerNode; ++tick)
      require_safe(prepared, state, ir.positions.col(node), remotes);
}

void probe(const PreparedIR& prepared, const HomeSpringPatch& patch) {
  EvaluationState state = make_evaluation_state(prepared);
  constexpr int kMaxProbedVertices = 16;
  for (int v = 0; v < std::min(patch.contact_vertex_count, kMaxProbedVertices); ++v) {
    const Eigen::Vector3d shaft = patch.rest_positions.col(v) - patch.trocar_pivot;
    for (double along : {0.5, 1.0, 1.2, 3.0})
      require_safe(prepared, state, patch.trocar_pivot + along * shaft, {});
    require_safe(prepared, state, patch.rest_positions.col(v) + Eigen::Vector3d(shaft.norm(), 0, 0),
                 {});
  }
}

void probe(const PreparedIR& prepared, const SeparationIr& ir) {
  EvaluationState state = make_evaluation_state(prepared);
  const SeparationPatch& patch = *ir.patch;
  const double extent = std::max(
      (patch.positions.rowwise().maxCoeff() - patch.positions.rowwise().minCoeff()).norm(), 1e-6);
  constexpr int kMaxProbedTriangles = 16, kTicksPerMove = 8;
  for (int t = 0; t < std::min(patch.triangle_count(), kMaxProbedTriangles); ++t) {
    const Eigen::Vector3d& centre = patch.centroids[static_cast<std::size_t>(t)];
    const Eigen::Vector3d& normal = patch.normals[static_cast<std::size_t>(t)];
    require_safe(prepared, state, centre, {}, 0);  // jaws open
    for (int tick = 1; tick <= kTicksPerMove; ++tick)
      require_safe(prepared, state, centre + 0.1 * extent * tick / kTicksPerMove * normal, {}, 3);
    for (int tick = 1; tick <= kTicksPerMove; ++tick)
      require_safe(prepared, state,
                   centre + 0.1 * extent * (normal + Eigen::Vector3d(tick, 0, 0) / kTicksPerMove),
                   {}, 3);
  }
  const Eigen::Vector3d from = patch.positions.col(0),
                        to = patch.positions.col(patch.node_count() - 1);
  for (int tick = 0; tick <= 4 * kTicksPerMove; ++tick)
    require_safe(prepared, state, from + (to - from) * tick / (4.0 * kTicksPerMove), {}, 1);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  wire::IntermediateRepresentation message;
  if (!message.ParseFromArray(data, static_cast<int>(size))) return 0;
  PreparedIR prepared;
  try {
    IntermediateRepresentation ir = wire::from_wire(message);
    if (auto* fem = std::get_if<CondensedFemIr>(&ir.body)) {
      ClientCondensation client;
      client.complete(*fem);
    }
    prepared = prepare_ir(std::move(ir));
  } catch (const Error&) {
    return 0;  // refused with a message: what a lying IR should get
  }
  std::visit([&prepared](const auto& body) { probe(prepared, body); }, prepared.ir.body);
  return 0;
}
