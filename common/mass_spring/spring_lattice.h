// A box lattice of springs: the several-objects paper's front object A (Sec. 3.1: 69 nodes,
// 291 lines, springs of 100 N/m, dampers of 0.10 N s/m, nodes of 0.05 kg). The box is
// cut into tetrahedra (box_mesher.h), a spring-damper runs along every tetrahedron edge
// (springs_along_edges.h, the paper's "lines"), every node has the same mass, and the
// surface a tool and the body behind touch is the tetrahedra's boundary. The lattice's
// "sections" (what an IR's sub-network counts, mass_spring_spec.h) are its layers of nodes
// across its longest axis.
// Units: m, N/m, N s/m, kg.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "common/mass_spring/mass_spring_network.h"

namespace cohaptic {

struct SpringLatticeSpec {
  Eigen::Vector3d min_corner = Eigen::Vector3d::Zero();  ///< [m]
  Eigen::Vector3d size = Eigen::Vector3d::Zero();        ///< [m], each > 0
  Eigen::Vector3i divisions = Eigen::Vector3i::Ones();   ///< cells per axis, each >= 1
  double spring_stiffness = 0;                           ///< every spring's k [N/m] > 0
  double spring_damping = 0;                             ///< every spring's k^d [N s/m] >= 0
  double node_mass = 0;                                  ///< every node's [kg] > 0
};

/// The network (nothing held, parameters left default); `section_of_node` is each node's
/// layer across the longest axis (the axis with the most divisions, the first of equals),
/// `section_count` their number.
struct SpringLattice {
  MassSpringNetwork network;
  std::vector<int> section_of_node;
  int section_count = 0;
};

/// Throws Error for a non-positive size, division, stiffness or mass, or negative damping.
SpringLattice spring_lattice(const SpringLatticeSpec& spec);

}  // namespace cohaptic
