// The thin-objects paper's tube (Fig. 7): cross-sections along a centre line, each with
// kRingNodes = 8 surface nodes on a circle of the tube's radius and one centre node.
// Node of section i: centre 9 i, ring node k at 9 i + 1 + k. Springs:
//   in a section: the ring (k, k+1) and the spokes (centre, k);
//   between sections i and i+1: the longitudinal (k, k), the diagonals (k, k±1), the
//   centre to the other section's ring nodes, and centre to centre;
// so an inner surface node has 8 surface and 3 centre neighbours, an inner centre node 24
// surface and 2 centre neighbours. The finite volume elements are the 8 wedge prisms
// (centre, k, k+1) between consecutive sections; Eq. (1) (Gelder),
//   k_c = E sum Vol(T_c) / |l_c|^2,
// sums the volumes of the elements holding both ends of the spring (which reproduces the
// ratios of the paper's Table 1), and Eq. (2) gives the damping k^d = alpha k. Each
// element's mass (density x volume) is shared equally by its six nodes. The surface is the
// ring quads (two triangles each) and a fan over each end section.
// Units: m, Pa, kg/m^3, s.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "common/mass_spring/mass_spring_network.h"

namespace cohaptic {

inline constexpr int kRingNodes = 8;
inline constexpr int kSectionNodes = kRingNodes + 1;

struct TubeGeometry {
  std::vector<Eigen::Vector3d> centre_line;  ///< polyline, at least 2 distinct points [m]
  double radius = 0;                         ///< [m]
  int sections = 2;                          ///< >= 2, evenly spaced along the polyline
  /// The ring's orientation: ring node 0 sits half a sector from the direction of `up`
  /// projected off the centre line, so that a tube lying on a plane with normal `up` rests
  /// on a flat face (two ring nodes).
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
};

struct TubeMaterial {
  double youngs_modulus = 0;  ///< E [Pa]
  double density = 0;         ///< [kg/m^3]
  double spring_damping = 0;  ///< alpha of Eq. (2) [s]
};

/// The nodes, masses, springs and surface of the tube (parameters left default, no node
/// held). Throws Error for a degenerate centre line, radius or section count.
MassSpringNetwork tube_network(const TubeGeometry& geometry, const TubeMaterial& material);

/// The wedge-prism elements of a tube of `sections` sections, each as its six nodes
/// (centre_i, ring_i k, ring_i k+1, centre_i+1, ring_i+1 k, ring_i+1 k+1).
std::vector<std::array<int, 6>> tube_elements(int sections);

/// Volume of a prism element at `positions`, split into three tetrahedra [m^3].
double prism_volume(const Eigen::Matrix3Xd& positions, const std::array<int, 6>& prism);

/// Volume enclosed by the network's (closed) surface at `positions` [m^3].
double enclosed_volume(const MassSpringNetwork& network, const Eigen::Matrix3Xd& positions);

}  // namespace cohaptic
