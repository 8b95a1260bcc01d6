// Collision of a tool with a mass–spring network's surface (the thin-objects paper,
// Sec. 4.2): find the surface node s_n nearest the tool, then the closest point on each
// triangle around s_n: the foot of the perpendicular on the triangle's plane if it lies
// inside the triangle (the three same-side tests of Eq. 4), else the closest point of its
// three edges (each the perpendicular foot if on the edge, else the nearer end). The
// nearest of these, x_s with its triangle's outward normal N_s, collides when
//   (x_s - x_h) . N_s >= -r       (Eq. 3, for a tool of radius r; r = 0 a point).
// Testing the faces rather than the nearest node alone avoids the false collisions of a
// sparse convex surface (Fig. 8). The contact node of Eq. (5) is s_n.
// Units: m. noexcept and allocation-free (the haptic path runs it).
#pragma once

#include <Eigen/Core>

#include "common/mass_spring/mass_spring_network.h"

namespace cohaptic {

struct SurfaceContact {
  bool colliding = false;
  int nearest_node = -1;                              ///< s_n, -1 for a network without surface
  int triangle = -1;                                  ///< the triangle of x_s
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    ///< x_s [m]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< N_s, unit outward
  double depth = 0;  ///< (x_s - x_h) . N_s + r [m]: >= 0 when colliding
};

SurfaceContact find_surface_contact(const MassSpringNetwork& network,
                                    const Eigen::Matrix3Xd& positions, const Eigen::Vector3d& tool,
                                    double radius) noexcept;

/// The closest point to p on triangle (sn, b, c) by the paper's construction (Eq. 4 for the
/// interior, then edges and their ends).
Eigen::Vector3d closest_point_on_face(const Eigen::Vector3d& p, const Eigen::Vector3d& sn,
                                      const Eigen::Vector3d& b, const Eigen::Vector3d& c) noexcept;

}  // namespace cohaptic
