// One user's instrument on a separating interface, one tick: forceps that grasp the flap
// while their jaws are closed, or a blunt tool that pushes on it, and optionally a laser
// fibre at the same tip. The same
// function runs on the server (the authoritative state) and on the client (its prediction
// within the current IR), each on its own copy of the state.
//
// Buttons (ToolSample.buttons, bit i = button i held):
//   - a tool without a laser: button 0 closes the jaws;
//   - a laser tool: button 0 fires the laser, button 1 closes the jaws.
// Jaws that close with the tip within `grasp_reach` of the interface grasp it at the
// nearest point (a grasp contact, separation_contact.h); opening them, or firing the
// laser, lets go. Jaws closed out of reach hold nothing until they open and close again.
// A pushing tool (contact push) has no jaws: whenever its tip is within `grasp_reach` of
// the interface and it holds no contact, it touches at the nearest point (a push contact:
// it slides by friction, stops at crack edges and lets go when it would pull); firing its
// laser lifts it off.
// The fibre vaporises along the tip's path while firing (laser_groove.h).
// The force on the hand is the contact's (zero while firing or not grasping).
// noexcept, no allocation. Units: m, s, N.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "common/separation/laser_groove.h"
#include "common/separation/separation_contact.h"

namespace cohaptic {

struct SeparationToolSettings {
  bool laser = false;         ///< the tool carries a fibre
  double grasp_reach = 1e-3;  ///< jaws closing (a pusher's tip) this near hold it [m]
  ContactMode contact = ContactMode::grasp;  ///< grasp (forceps) or push (a blunt tool)
};

inline constexpr std::uint32_t kLaserFireButton = 1u;  ///< button 0 of a laser tool

/// The button that closes the jaws: button 1 on a laser tool, button 0 otherwise.
inline std::uint32_t jaw_button(const SeparationToolSettings& settings) noexcept {
  return settings.laser ? 2u : 1u;
}

struct SeparationToolState {
  SeparationContact contact;
  LaserFibre fibre;
  bool jaws_closed = false;  ///< at the previous tick: a grasp begins when they close
};

struct SeparationToolSample {
  SeparationSample contact;
  LaserSample laser;
  double distance = 0;  ///< from the tip to the interface [m]
};

/// The point of the patch nearest `p` (a point tool: tool node 0), and its distance [m].
ContactPoint nearest_patch_point(const SeparationPatch& patch, const Eigen::Vector3d& p,
                                 double& distance) noexcept;

/// One tick of length dt [s] with the tip at `tip` and `buttons` held.
SeparationToolSample step_separation_tool(const SeparationPatch& patch, SeparationState& state,
                                          SeparationToolState& tool,
                                          const SeparationToolSettings& settings,
                                          const Eigen::Vector3d& tip, std::uint32_t buttons,
                                          double dt) noexcept;

}  // namespace cohaptic
