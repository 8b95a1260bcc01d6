// ShownSurface: the part of an object's surface that can be drawn deformed, for the
// display frames (.vtu files) and the live view: the nodes with compliance rows (whose
// displacement the simulation solves, Simulation::displacement_of) and the surface
// triangles whose three nodes all have rows, renumbered over those nodes.
#pragma once

#include <span>
#include <vector>

#include "common/model/elastic_body.h"

namespace cohaptic {

struct ShownSurface {
  std::vector<int> nodes;           ///< volume node indices, in the order given
  std::vector<Triangle> triangles;  ///< outward, indices into `nodes`
  std::vector<int> index_of;        ///< per volume node: its index in `nodes`, or -1
};

/// The surface over `row_nodes` (a ComplianceColumns' row nodes).
ShownSurface shown_surface(const ElasticBody& body, std::span<const int> row_nodes);

}  // namespace cohaptic
