// Two linear-elastic bodies that share a triangulated interface: the pulled body (the
// flap a tool separates) and the base it is attached to (the separation-forces paper's
// B1 and B2, Sec. IV).
//
// The bodies are meshed separately with conforming nodes on the common surface: every
// interface node of the pulled body coincides with one of the base. Interface node k is
// the pair (pulled_nodes[k], base_nodes[k]); interface triangles use interface node
// indices and are oriented so that (p1 - p0) x (p2 - p0) points from the base into the
// pulled body: the direction in which the pulled body is lifted off ("opening").
// Rim edges (edges of one interface triangle only) are where a crack may start, unless
// sealed (where the layers continue beyond the model). Units: m, Pa.
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <vector>

#include "common/fem/dof_map.h"
#include "common/fem/linear_elastic_material.h"
#include "common/mesh/tet_mesh.h"

namespace cohaptic {

struct SeparationBody {
  TetMesh mesh;
  LinearElasticMaterial material;
  std::vector<AxisMask> fixed_axes;  ///< per node: the supports
};

struct SeparationBodies {
  SeparationBody pulled;  ///< B1: the body the tool pulls away; needs supports of its own
  SeparationBody base;    ///< B2: the body it is attached to
};

struct SeparationInterface {
  std::vector<int> pulled_nodes;    ///< per interface node: its node in the pulled body
  std::vector<int> base_nodes;      ///< per interface node: the coincident node of the base
  Eigen::Matrix3Xd positions;       ///< per interface node: rest position [m]
  std::vector<Triangle> triangles;  ///< interface node indices, normal into the pulled body
  /// Per triangle, the triangle across edge (k, k+1), or -1 on the rim.
  std::vector<std::array<int, 3>> neighbours;
  /// Per triangle, bit k set: edge (k, k+1) is a rim edge where a crack may start.
  std::vector<std::uint8_t> open_rim;

  int node_count() const { return static_cast<int>(pulled_nodes.size()); }
  int triangle_count() const { return static_cast<int>(triangles.size()); }
};

/// The common surface of the two bodies: boundary nodes that coincide within `tolerance`
/// [m], and the boundary triangles of the pulled body whose three nodes pair with the
/// nodes of a boundary triangle of the base. Every rim edge starts open. Throws Error if
/// the bodies share no triangle, or a pulled node has two base nodes within tolerance.
SeparationInterface find_interface(const SeparationBodies& bodies, double tolerance);

/// Closes the rim edges both of whose nodes satisfy `sealed_node` (an interface node index):
/// where the layers go on beyond the model.
void seal_rim_edges(SeparationInterface& interface, const std::function<bool(int)>& sealed_node);

/// Two stacked boxes, relative to `origin`: the base [0, a] x [0, b] x [-base_thickness, 0]
/// and the pulled layer [0, a] x [0, b] x [0, pulled_thickness], with the same divisions in
/// x and y so that their nodes conform on the interface z = 0.
struct TwoLayerBoxes {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< the interface's corner [m]
  Eigen::Vector2d size{0.04, 0.04};                  ///< a, b [m]
  double pulled_thickness = 0.004;                   ///< [m]
  double base_thickness = 0.01;                      ///< [m]
  Eigen::Vector2i divisions{20, 20};
  int pulled_layers = 2;
  int base_layers = 3;
  LinearElasticMaterial pulled_material{.youngs_modulus = 60e3, .poisson_ratio = 0.45};
  LinearElasticMaterial base_material{.youngs_modulus = 60e3, .poisson_ratio = 0.45};
};

/// The two layers with their supports: the base held on its bottom face, the pulled layer
/// on its end face x = origin.x + a above the interface (the flap goes on into tissue there; its
/// interface nodes stay free). Seal the rim at that end on the found interface.
SeparationBodies make_two_layer_boxes(const TwoLayerBoxes& boxes);

}  // namespace cohaptic
