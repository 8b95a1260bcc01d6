// Springs along the edges of a tetrahedral mesh: the several-objects paper's front object
// A (Sec. 3.1: 158 tetrahedra, 69 nodes, 291 lines) is a mass-spring network whose lines
// are its tetrahedra's edges, all of one stiffness and damping. Each edge once, (a < b),
// in ascending order; rest length the edge's length at the mesh's rest positions.
// Units: m, N/m, N s/m.
#pragma once

#include <vector>

#include "common/mass_spring/mass_spring_network.h"
#include "common/mesh/tet_mesh.h"

namespace cohaptic {

/// Throws Error when an edge has no length (two nodes at one point).
std::vector<Spring> springs_along_edges(const TetMesh& mesh, double stiffness, double damping);

}  // namespace cohaptic
