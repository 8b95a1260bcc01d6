// One tool's contact with a separating interface, stepped at the haptic rate: the force
// (Algorithm V.2), sliding, and fracture by normal and tangential forces (Sec. V.D, V.F).
// The same function runs on the server (P0) and on the client (P1), each on its own copy
// of the state: MuJoCo style, the patch is immutable and the state is passed explicitly.
//
// A contact holds c, the contact point on the patch (at rest), the tool triangle's
// weights, and the tool's offset when it began, so that the deflection delta = x - offset
// - c starts at zero. Each tick, with the tool's contact point x:
//   1. fracture (fracture_step.h): where a crack front lies in the contact's region, the
//      force that opens it is held at J_c l — F_n = J_c l_n pulling away, F_t = J_c l_t
//      pushing along — while the crack grows by l per metre of the move. When the
//      contact's region is used up, a push along the interface carries c on with the crack
//      edge at the threshold (Fig. 3); a straight pull loads the separated flap;
//   2. a pushing tool lets go if its normal force would pull (F . n < 0);
//   3. a pushing tool slides by friction, c moving along the tangential deflection until
//      |F_t| = mu (F . n); sliding, c stops at a crack edge (an edge between an open and a
//      closed triangle: "the contact point c stops sliding if it reaches a crack edge",
//      Sec. V.D) and at the rim. A grasp does not slide;
//   4. the force on the hand is -F, scaled down to the force limit, zero if not finite.
// c only moves forward, by slips that dissipate: the contact is passive.
// noexcept, lock-free, no allocation. Units: m, N, J.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "common/separation/separation_force.h"

namespace cohaptic {

enum class ContactMode : std::uint8_t {
  none,
  grasp,  ///< holds the tissue: pulls and pushes, never slides by friction
  push,   ///< presses on an exposed layer: only pushes, slides by friction
};

struct SeparationContact {
  ContactMode mode = ContactMode::none;
  ContactPoint point;                                     ///< c's triangle and weights, the tool's
  Eigen::Vector3d position = Eigen::Vector3d::Zero();     ///< c [m], at rest
  Eigen::Vector3d tool_offset = Eigen::Vector3d::Zero();  ///< x - c when the contact began [m]
  Eigen::Vector3d last_tool = Eigen::Vector3d::Zero();    ///< x at the previous tick [m]
};

enum SeparationFlag : std::uint16_t {
  kSeparationInContact = 1,
  kSeparationFracture = 2,
  kSeparationSliding = 4,
  kSeparationStoppedAtCrackEdge = 8,
  kSeparationReleased = 16,
  kSeparationClamped = 32,
  kSeparationNonFinite = 64,
  kSeparationAboveThreshold = 128,  ///< fracture could not hold the force at its threshold
};

struct SeparationSample {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();       ///< on the hand: -F, limited [N]
  Eigen::Vector3d body_force = Eigen::Vector3d::Zero();  ///< F on the pulled body [N]
  Eigen::Vector3d deflection = Eigen::Vector3d::Zero();  ///< delta [m]
  double energy = 0;                                     ///< the fields' potential at delta [J]
  double separated = 0;        ///< area separated by fracture this tick [m^2]
  double fracture_motion = 0;  ///< the part of the tool's move that fractured [m]
  std::uint16_t flags = 0;
};

/// A contact at `point` (c on its patch triangle) with the tool's contact point at `tool`.
/// Mode none (no contact) if the triangle, a tool node or a weight is invalid.
SeparationContact begin_contact(const SeparationPatch& patch, ContactMode mode,
                                const ContactPoint& point, const Eigen::Vector3d& tool) noexcept;

/// The deflection the fields see.
inline Eigen::Vector3d contact_deflection(const SeparationContact& contact,
                                          const Eigen::Vector3d& tool) noexcept {
  return tool - contact.tool_offset - contact.position;
}

SeparationSample step_contact(const SeparationPatch& patch, SeparationState& state,
                              SeparationContact& contact, const Eigen::Vector3d& tool) noexcept;

}  // namespace cohaptic
