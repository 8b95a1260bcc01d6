// An instrument's shaft through its trocar: the device gives only the tool point, and the
// shaft's direction follows from it and the trocar pivot the scene declares (the
// instrument pivots about the incision). The jaws of forceps open in a plane through the
// shaft; its roll about the shaft is the scene's opening direction projected
// perpendicular to the shaft (so no orientation travels on the wire).
// Units: m; directions are unit vectors.
#pragma once

#include <Eigen/Core>
#include <optional>

namespace cohaptic {

struct ShaftFrame {
  Eigen::Vector3d pivot;    ///< the trocar pivot [m]
  Eigen::Vector3d tool;     ///< the tool point: a probe's tip A, forceps' jaw junction B [m]
  Eigen::Vector3d axis;     ///< unit, from the pivot towards the tool
  Eigen::Vector3d opening;  ///< unit, perpendicular to axis: the jaws open along +-opening
};

/// The frame of the shaft from `pivot` to `tool`, or nullopt when the tool is at the pivot
/// or a point is not finite. When `opening_hint` is parallel to the shaft (or zero) any
/// fixed perpendicular is used. noexcept and allocation-free.
std::optional<ShaftFrame> shaft_frame(const Eigen::Vector3d& pivot, const Eigen::Vector3d& tool,
                                      const Eigen::Vector3d& opening_hint) noexcept;

}  // namespace cohaptic
