// One haptic tick of the home-spring body: where the instrument touches the patch and the
// force it feels (the laparoscopy paper's collision point, closest vertex and Eq. 8).
//
// Not grasping: the shaft is the segment from the trocar pivot to the tool point; its
// first crossing of the patch's rest surface (from the pivot) is the collision point P,
// the crossed triangle's corner nearest P is the vertex the force acts on, and that vertex
// is displaced by u = tool - P (along the shaft: the tool pushes the surface point it went
// through to where it is now). No crossing: no contact, zero force. Grasping: the grasped
// vertex follows the tool from where the jaws closed, u = tool - tool_at_grasp.
// The force on the tool is -F_total of Eq. 8 (home_spring_force.h). Preparing builds the
// patch's AABB tree (allocates, throws on an invalid patch); evaluating is noexcept and
// allocation-free, and a tool point that is not finite gives no contact. Units: m, N.
#pragma once

#include <Eigen/Core>

#include "common/contact/aabb_tree.h"
#include "common/laparoscopy/home_spring_patch.h"

namespace cohaptic {

struct PreparedHomeSpringPatch {
  HomeSpringPatch patch;
  AabbTree rest_surface;  ///< over patch.triangles at rest
};

/// Validates `patch` (Error naming what is wrong) and builds its tree.
PreparedHomeSpringPatch prepare_home_spring_patch(HomeSpringPatch patch);

struct HomeSpringContact {
  bool touching = false;
  int vertex = -1;                                          ///< patch vertex the force acts on
  Eigen::Vector3d contact_point = Eigen::Vector3d::Zero();  ///< P on the rest surface [m]
  Eigen::Vector3d displacement = Eigen::Vector3d::Zero();   ///< u = P_current - P_original [m]
  Eigen::Vector3d force = Eigen::Vector3d::Zero();          ///< on the tool, -F_total [N]
};

HomeSpringContact evaluate_home_spring(const PreparedHomeSpringPatch& prepared,
                                       const Eigen::Vector3d& tool) noexcept;

}  // namespace cohaptic
