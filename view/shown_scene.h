// ShownScene: what the live view draws of a scene: every body's shown surface, concatenated
// in the model's order (one part per body, its shown nodes numbered from the part's offset),
// with the rest positions and triangles the Scene message carries once. Per body kind:
//   linear elastic  the nodes with compliance rows and the surface triangles over them
//                   (common/model/shown_surface.h), displaced by the state's loads;
//   mass-spring     the network's surface nodes and triangles, displaced to their positions;
//   home-spring     the tissue's surface, dented as its display deformation dents it;
//   separation      both layers' boundary surfaces (pulled layer first) at rest: its
//                   simulation holds the separated area, no displacement field.
// Units: m. Invariant: parts[i] is model body i; a part's nodes are shown nodes
// [offset, offset + nodes.size()).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "common/fem/compliance.h"
#include "common/laparoscopy/tissue_display.h"
#include "common/model/model.h"

namespace cohaptic::view {

struct ShownPart {
  int offset = 0;  ///< its first shown node
  /// Per shown node of the part, the body's node: a volume node (linear elastic), a network
  /// node (mass-spring), a surface vertex (home-spring), a layer node (separation: the
  /// pulled layer's, then the base's numbered on after them).
  std::vector<int> nodes;
  std::vector<int> index_of;       ///< per body node: its shown index (offset included), or -1
  std::vector<int> row_positions;  ///< linear elastic: per node, ComplianceColumns::row_position
  std::unordered_map<std::int64_t, int> shown_of_tag;  ///< linear elastic: mesh tag -> shown index
  const TissueDisplay* display = nullptr;  ///< home-spring: its display deformation's setup

  int size() const { return static_cast<int>(nodes.size()); }
};

struct ShownScene {
  Eigen::Matrix3Xd rest;            ///< per shown node, at rest [m]
  std::vector<Triangle> triangles;  ///< shown node indices, as each body's surface orients them
  std::vector<ShownPart> parts;     ///< one per model body

  int node_count() const { return static_cast<int>(rest.cols()); }
  /// The shown index of body `body`'s node `node` (ShownPart::nodes' numbering), or -1.
  int of_node(int body, int node) const;
  /// The shown index of linear elastic body `body`'s node with mesh tag `tag`, or -1.
  int of_tag(int body, std::int64_t tag) const;
};

/// The shown scene of `model`; columns[i] holds body i's compliance columns when it is linear
/// elastic (null otherwise). The model and the columns must outlive it.
ShownScene shown_scene(const Model& model, std::span<ComplianceColumns* const> columns);

}  // namespace cohaptic::view
