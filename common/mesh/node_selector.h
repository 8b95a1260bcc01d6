// NodeSelector: which nodes of a body a scene means, as the scene file says it
// (docs/scene-reference.md, "Node selectors"): its whole surface, the nodes inside a box, on a
// plane, or by tag. Plain data; it is resolved against a body's nodes when the body is built
// (select_nodes, common/model/elastic_body.h). Units: m.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace cohaptic {

/// Selects nodes of an object: on its whole surface, inside a box, on a plane, or by tag.
struct NodeSelector {
  enum class Kind { surface, box, plane, node_tags };
  Kind kind = Kind::surface;
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero(), box_max = Eigen::Vector3d::Zero();  ///< [m]
  Eigen::Vector3d plane_point = Eigen::Vector3d::Zero();                                 ///< [m]
  Eigen::Vector3d plane_normal = Eigen::Vector3d::UnitZ();                               ///< unit
  std::optional<double> tolerance;  ///< [m]; default: 1e-6 of the mesh's bounding-box diagonal
  std::vector<std::int64_t> node_tags;
  std::string where;  ///< "file:line: key.path" it came from, for messages
};

}  // namespace cohaptic
