// HomeSpringBody: a laparoscopy tissue compiled from its scene object (`model:
// home_spring`), never changed afterwards: the rest surface in metres, every vertex's
// 1-ring, an AABB tree over the triangles (the shafts' and jaws' crossings) and the display
// deformation's setup. One of the body kinds a Model holds (model.h).
//
// Invariant: the patch radius is at least the longest edge, so the patch around any vertex
// holds every triangle around it (the triangle a shaft crosses, whose corner nearest the
// crossing is the patch's centre, is always in the patch). Units: m, N/m.
#pragma once

#include <string>

#include "common/contact/aabb_tree.h"
#include "common/laparoscopy/home_spring_spec.h"
#include "common/laparoscopy/tissue_display.h"
#include "common/laparoscopy/vertex_rings.h"
#include "common/mesh/triangle_surface.h"

namespace cohaptic {

struct HomeSpringBody {
  std::string name;  ///< the scene object's name
  HomeSpringObjectSpec spec;
  TriangleSurface surface;  ///< at rest [m]
  VertexRings rings;
  AabbTree tree;            ///< over surface.triangles at rest
  TissueDisplay display;    ///< the display deformation over the surface's vertices
  double longest_edge = 0;  ///< [m]
};

/// Builds the body; throws SceneError naming `where` for a surface that cannot be read, has
/// no triangle or a degenerate one, or a patch radius below the longest edge. Surface files
/// are scaled by `metres_per_unit`.
HomeSpringBody build_home_spring_body(const std::string& name, const HomeSpringObjectSpec& spec,
                                      const std::string& where, double metres_per_unit);

}  // namespace cohaptic
