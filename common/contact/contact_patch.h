// The patch around a contact triangle: the surface triangles a sliding tool may reach
// before the next intermediate representation arrives.
//
// rings = 0 is the triangle alone; each further ring adds every allowed triangle that
// shares a vertex with the patch so far. The contact triangle comes first.
#pragma once

#include <span>
#include <vector>

#include "common/mesh/boundary_surface.h"

namespace cohaptic {

/// `allowed[t]` says whether surface triangle t may join (touchable, and free of held nodes).
std::vector<int> contact_patch(const BoundarySurface& surface, int triangle, int rings,
                               const std::vector<bool>& allowed);

/// The same grown from several triangles at once; `seeds` come first, in their order.
std::vector<int> contact_patch(const BoundarySurface& surface, std::span<const int> seeds,
                               int rings, const std::vector<bool>& allowed);

}  // namespace cohaptic
