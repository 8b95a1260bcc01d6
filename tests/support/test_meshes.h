// Meshes shared by tests and benchmarks.
#pragma once

#include <random>
#include <string>

#include "common/mesh/tet_mesh.h"
#include "common/mesh/triangle_surface.h"

namespace cohaptic::testing {

/// Unit-less box mesh [0,size]^3 whose interior nodes are moved by up to `jitter` of a
/// cell (seeded), so that no element is aligned with the axes. Boundary nodes stay on
/// the box faces (moved only within their face) so the box keeps its shape.
TetMesh distorted_box_mesh(double size, int divisions, double jitter, unsigned seed);

/// Icosahedron subdivided `level` times (each triangle into four), vertices on the sphere
/// of `radius`, triangles counter-clockwise seen from outside: 20 * 4^level triangles.
TriangleSurface make_icosphere(int level, double radius);

/// A uniformly distributed unit vector.
Eigen::Vector3d random_direction(std::mt19937& rng);

/// Path of a file under the source tree (tests read their data from tests/data).
std::string source_path(const std::string& relative);

}  // namespace cohaptic::testing
