// A laparoscopy tissue generated from the scene (`surface: {grid: ...}`): a flat sheet of
// rectangular cells split along one diagonal, counter-clockwise seen from +z, so that the
// shaft of an instrument above it crosses it from outside. Vertex (i, j) is column
// i + (divisions.x + 1) j; its rest position is min + (i size.x / divisions.x,
// j size.y / divisions.y, 0). The vertices are those of the top face of a box mesh with the
// same min, size and divisions (box_mesher.h), so an FEM slab can stand in for the same
// tissue. Units: m.
#pragma once

#include "common/laparoscopy/home_spring_spec.h"
#include "common/mesh/triangle_surface.h"

namespace cohaptic {

TriangleSurface tissue_grid(const TissueGridSpec& grid);

}  // namespace cohaptic
