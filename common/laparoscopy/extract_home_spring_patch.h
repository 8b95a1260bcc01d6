// The server's half of the home-spring body: the patch of a body's surface around a
// point, with everything Eq. 8 needs there (see home_spring_patch.h).
//
// The touchable region is every surface triangle whose three corners lie within `radius`
// of `centre`; its corners are the touchable vertices (in increasing surface index), and
// the rest of their 1-rings on the whole surface follow as ring-only vertices. Off the
// haptic path: it allocates. Units: m, N/m, N s/m.
#pragma once

#include <Eigen/Core>
#include <span>

#include "common/laparoscopy/home_spring_patch.h"
#include "common/laparoscopy/vertex_rings.h"

namespace cohaptic {

struct HomeSpringSurface {
  const Eigen::Matrix3Xd& rest_positions;  ///< the body's surface vertices at rest [m]
  std::span<const Triangle> triangles;
  const VertexRings& rings;  ///< vertex_rings(triangles, vertex count)
};

struct HomeSpringConstants {
  double home = 0;       ///< k1 [N/m]
  double neighbour = 0;  ///< k2 [N/m]
  double damping = 0;    ///< c [N s/m]
};

/// The validated patch within `radius` of `centre`, not grasped; throws Error when no
/// triangle lies wholly within reach (naming the centre and the radius).
HomeSpringPatch extract_home_spring_patch(const HomeSpringSurface& surface,
                                          const Eigen::Vector3d& centre, double radius,
                                          const HomeSpringConstants& constants,
                                          const Eigen::Vector3d& trocar_pivot);

}  // namespace cohaptic
