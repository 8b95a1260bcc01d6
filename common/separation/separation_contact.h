// One tool's contact with a separating interface, stepped at the haptic rate: the force
// (Algorithm V.2), sliding, and fracture by normal and tangential forces (Sec. V.D, V.F).
// The same function runs on the server (P0) and on the client (P1), each on its own copy
// of the state: MuJoCo style, the patch is immutable and the state is passed explicitly.
//
// A contact holds c, the contact point on the patch (at rest), the tool triangle's
// weights, and the tool's offset when it began, so that the deflection delta = x - offset
// - c starts at zero. Each tick, with the tool's contact point x:
//   1. normal fracture (normal_fracture.h), c fixed;
//   2. tangential: with n the normal of c's triangle and F_t the tangential force, the
//      limit is mu (F . n) for a pushing tool (it slides by friction; a grasp does not)
//      and F_t = J_c l_t where a crack front lies in the contact's region. Above the
//      limit, c moves along the tangential deflection until |F_t| is back at it. A
//      sliding c stops at a crack edge (and at the rim); pushed on past it at F_t, the
//      crack edge moves with the tool and l_t times the distance separates (Eqs. 4–11).
//   3. the force on the hand is -F, scaled down to the force limit, zero if not finite.
// A pushing tool lets go when its normal force would pull (F . n < 0).
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
  kSeparationNormalFracture = 2,
  kSeparationTangentialFracture = 4,
  kSeparationSliding = 8,
  kSeparationStoppedAtCrackEdge = 16,
  kSeparationReleased = 32,
  kSeparationClamped = 64,
  kSeparationNonFinite = 128,
  kSeparationAboveThreshold = 256,  ///< fracture could not hold the force at its threshold
};

struct SeparationSample {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();       ///< on the hand: -F, limited [N]
  Eigen::Vector3d body_force = Eigen::Vector3d::Zero();  ///< F on the pulled body [N]
  Eigen::Vector3d deflection = Eigen::Vector3d::Zero();  ///< delta [m]
  double energy = 0;           ///< the fields' potential at delta [J]
  double separated = 0;        ///< area separated by fracture this tick [m^2]
  double fracture_motion = 0;  ///< the tool's travel that fractured: dz_f + tangential [m]
  std::uint16_t flags = 0;
};

/// A contact at `point` (c on its patch triangle) with the tool's contact point at `tool`.
/// Mode none (no contact) if the triangle, a tool node or a weight is invalid.
SeparationContact begin_contact(const SeparationPatch& patch, ContactMode mode, const ContactPoint& point,
                                const Eigen::Vector3d& tool) noexcept;

/// The deflection the fields see.
inline Eigen::Vector3d contact_deflection(const SeparationContact& contact, const Eigen::Vector3d& tool) noexcept {
  return tool - contact.tool_offset - contact.position;
}

SeparationSample step_contact(const SeparationPatch& patch, SeparationState& state, SeparationContact& contact,
                              const Eigen::Vector3d& tool) noexcept;

}  // namespace cohaptic
