// MassSpringIr: the IR body of a mass–spring object (the thin-objects paper's model): the
// sub-network around a user's contact, as the server's state had it at the IR's
// simulation time. The client integrates it at the haptic rate with the same functions the
// server runs (common/mass_spring/tool_coupling.h) and feels Eq. (5)'s force; the server
// stays authoritative and sends a fresh one at the body's IR rate.
//
// Nodes are the body's nodes within `sections` cross-sections of the contact's on each
// side, plus one held section beyond on each side (the rim: it moves at the server's
// velocity, standing in for the rest of the body); the whole body when it is small. Springs
// and triangles are those with every end inside, in local indices. The presses carry each
// tool's contact memory (own first, then the remote tools in remote_users' order), so that
// the client continues exactly where the server's whole-network step left off.
// A body behind this one (a scene interaction) comes as the backing on the sub-network's
// nodes that press it (node_backing.h: B's normal compliance over them; the server's pushes
// on backed nodes outside the sub-network are held, as the rim is, and enter as the
// offsets), so the client feels the behind body through this one.
// Units: m, m/s, kg, N/m, N s/m, s.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "common/mass_spring/mass_spring_network.h"
#include "common/mass_spring/node_backing.h"
#include "common/mass_spring/tool_coupling.h"

namespace cohaptic {

struct MassSpringIr {
  std::vector<std::int32_t> node_ids;  ///< the body's node index, per local node
  Eigen::Matrix3Xd positions;          ///< [m]
  Eigen::Matrix3Xd velocities;         ///< [m/s]
  Eigen::VectorXd mass;                ///< [kg]
  std::vector<std::uint8_t> held;      ///< 1: rim (or pinned) node
  std::vector<Spring> springs;
  std::vector<std::array<int, 3>> triangles;
  MassSpringParameters parameters;
  std::vector<int> remote_users;     ///< the other users whose tools act on the sub-network
  std::vector<double> remote_radii;  ///< their tool radii [m]
  std::vector<ToolPress> presses;    ///< 1 + remote_users.size(): own, then remotes
  NodeBacking backing;               ///< local nodes; empty: nothing behind the body

  int node_count() const { return static_cast<int>(node_ids.size()); }
  /// Bytes of the content as sent.
  std::size_t size_bytes() const;
};

}  // namespace cohaptic
