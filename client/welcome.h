// What a client takes from the server's Welcome (messages.proto): its slot, the scene, the
// protocol and the haptic settings, checked before any of it reaches the haptic loop.
//
// welcome_info() throws cohaptic::Error naming the first field that a correct server never
// sends: a slot that is not among the users, an unspecified protocol, a force limit that is
// not in (0, 1000] N, a haptic rate outside [1, 100000] Hz (the scene's ranges), or an IR
// age limit that is not a positive, finite time. A NaN force limit, for one, would switch
// the haptic loop's limiting off. Units: N, Hz, s, m.
#pragma once

#include <Eigen/Geometry>

#include <string>

#include "cohaptic/messages.pb.h"
#include "client/haptic_loop.h"

namespace cohaptic {

/// What the server told us when we joined.
struct WelcomeInfo {
  int slot = 0;
  std::string scene_name;
  std::string scene_yaml;
  HapticProtocol protocol = HapticProtocol::p1;
  double force_limit = 0;
  double haptic_rate_hz = 1000;
  double ir_max_age_s = 0.5;
  int user_count = 0;
  Eigen::AlignedBox3d surface_bounds;  ///< of the scene's surface's finite vertices; empty if none
};

/// The Welcome's content, validated as described above.
WelcomeInfo welcome_info(const wire::Welcome& welcome);

}  // namespace cohaptic
