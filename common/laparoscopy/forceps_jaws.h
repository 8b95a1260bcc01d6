// Forceps (or scissors) as the laparoscopy paper models them: the triangle A1 A2 B, two
// jaws B -> A_k hinged at the junction B (the tool point) and opened symmetrically about
// the shaft in the opening plane. While the button is held the jaws close about B in
// fixed increments, one increment per step, and each jaw stops at the first angle at
// which it crosses the object's surface; when both have stopped on it the tissue is
// grasped: the grasp point (midway between the two jaws' contacts with the surface) and the
// tool point at that moment are kept until the button is released, whatever the tool
// does. Jaws that close fully without touching stay closed, grasping nothing. Button up
// opens both jaws and releases. step_forceps is noexcept and allocation-free.
// Units: m, rad (a jaw's angle is measured from the shaft axis; 0 is closed).
#pragma once

#include <Eigen/Core>
#include <array>

#include "common/contact/aabb_tree.h"
#include "common/laparoscopy/trocar_shaft.h"

namespace cohaptic {

struct ForcepsGeometry {
  double jaw_length = 0.02;    ///< |B A_k| [m]
  double open_angle = 0.5;     ///< each jaw's angle from the axis when open [rad]
  double closing_step = 0.01;  ///< closing increment per step while the button is held [rad]
};

struct ForcepsJaws {
  std::array<double, 2> angle{};  ///< from the axis [rad]; jaw 0 on +opening
  std::array<bool, 2> stopped{};  ///< stopped by the object
  std::array<Eigen::Vector3d, 2> contact{
      Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};  ///< where each crossed the surface [m]
  bool grasping = false;
  Eigen::Vector3d grasp_point =
      Eigen::Vector3d::Zero();  ///< midway between the contacts, held while grasping [m]
  Eigen::Vector3d tool_at_grasp = Eigen::Vector3d::Zero();  ///< B when both jaws stopped [m]
};

/// Jaws wide open, nothing grasped. Throws Error when the geometry is not positive and
/// finite or the opening is not below pi/2.
ForcepsJaws open_forceps(const ForcepsGeometry& geometry);

/// The jaw tips A1 (jaw 0) and A2 (jaw 1) for the current angles.
std::array<Eigen::Vector3d, 2> jaw_tips(const ForcepsGeometry& geometry, const ShaftFrame& shaft,
                                        const ForcepsJaws& jaws) noexcept;

/// One step of the jaws against `surface` (the object's rest surface) with the button
/// `closing` held or not.
void step_forceps(const ForcepsGeometry& geometry, const ShaftFrame& shaft, bool closing,
                  const AabbTree& surface, ForcepsJaws& jaws) noexcept;

}  // namespace cohaptic
