// A flat tissue sheet for the laparoscopy tests and benchmarks: equilateral triangles of
// side `spacing` in the plane z = 0, centred on the origin, counter-clockwise seen from
// +z. Every interior vertex has a regular hexagonal 1-ring of radius `spacing`, and the
// nearest vertex to any point of the sheet is a corner of the triangle containing it.
#pragma once

#include "common/mesh/triangle_surface.h"

namespace cohaptic::testing {

/// (columns + 1) x (rows + 1) vertices, 2 columns rows triangles.
TriangleSurface equilateral_sheet(int columns, int rows, double spacing);

}  // namespace cohaptic::testing
