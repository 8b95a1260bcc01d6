#include "common/mass_spring/spring_lattice.h"

#include <fmt/format.h>

#include "common/mass_spring/springs_along_edges.h"
#include "common/mesh/boundary_surface.h"
#include "common/mesh/box_mesher.h"
#include "common/util/error.h"

namespace cohaptic {

SpringLattice spring_lattice(const SpringLatticeSpec& spec) {
  if (!(spec.size.array() > 0).all() || !(spec.divisions.array() >= 1).all())
    throw Error("a spring lattice needs a positive size and at least one division along each axis");
  if (!(spec.spring_stiffness > 0) || !(spec.spring_damping >= 0) || !(spec.node_mass > 0))
    throw Error(fmt::format(
        "a spring lattice needs a positive spring stiffness ({}) and node mass ({}) and a "
        "non-negative spring damping ({})",
        spec.spring_stiffness, spec.node_mass, spec.spring_damping));
  SpringLattice lattice;
  const TetMesh mesh = make_box_mesh(spec.min_corner, spec.size, spec.divisions);
  MassSpringNetwork& network = lattice.network;
  network.rest_positions = mesh.nodes;
  network.mass = Eigen::VectorXd::Constant(mesh.node_count(), spec.node_mass);
  network.held.assign(static_cast<std::size_t>(mesh.node_count()), 0);
  network.springs = springs_along_edges(mesh, spec.spring_stiffness, spec.spring_damping);
  network.triangles = extract_boundary_surface(mesh).triangles;
  index_surface(network);

  // box_mesher.h numbers the nodes x fastest, then y, then z.
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (spec.divisions[a] > spec.divisions[axis]) axis = a;
  const Eigen::Vector3i points = spec.divisions.array() + 1;
  const int stride = axis == 0 ? 1 : axis == 1 ? points.x() : points.x() * points.y();
  lattice.section_count = points[axis];
  for (int n = 0; n < mesh.node_count(); ++n)
    lattice.section_of_node.push_back(n / stride % points[axis]);
  return lattice;
}

}  // namespace cohaptic
