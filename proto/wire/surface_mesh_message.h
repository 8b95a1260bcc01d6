// The model's boundary surface as sent in Welcome.surface, for the client's display and
// its own contact geometry.
//
// Vertices are the surface nodes in a compact numbering: vertex i is the i-th of
// body.surface.nodes (ascending volume node index), at its rest position [m];
// triangles are the surface triangles (outward, counter-clockwise seen from outside) in
// that numbering; node_ids[i] is the mesh tag of vertex i (the ids users see).
#pragma once

#include <cstdint>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "common/mesh/triangle_surface.h"
#include "common/model/elastic_body.h"
#include "common/model/model.h"

namespace cohaptic::wire {

SurfaceMesh surface_mesh_message(const ElasticBody& body);
/// A mass-spring body's surface at rest: vertex i is network.surface_nodes[i], its node id
/// the network's node index.
SurfaceMesh surface_mesh_message(const MassSpringModel& body);
/// A home-spring tissue's surface at rest: vertex i is surface vertex i, its node id i.
SurfaceMesh surface_mesh_message(const HomeSpringBody& body);
/// A separating-tissue body's interface at rest (what its tools grasp): vertex i is
/// interface node i, its node id i.
SurfaceMesh surface_mesh_message(const SeparationModel& body);
/// Whichever kind `body` is.
SurfaceMesh surface_mesh_message(const BodyModel& body);

/// A received surface: its triangles and each vertex's mesh node id.
struct ReceivedSurface {
  TriangleSurface surface;             ///< [m]
  std::vector<std::int64_t> node_ids;  ///< per vertex
};

/// Validated conversion: vertices a multiple of 3 and finite, one node id per vertex,
/// triangles a multiple of 3 with indices in range. Throws cohaptic::Error naming the
/// first problem.
ReceivedSurface from_wire(const SurfaceMesh& mesh);

}  // namespace cohaptic::wire
