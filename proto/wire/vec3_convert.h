// Vec3 (wire) <-> Eigen::Vector3d: three doubles, bit for bit, in the same units (m, N or
// unit vectors, whatever the field says).
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "cohaptic/messages.pb.h"

namespace cohaptic::wire {

inline void to_wire(const Eigen::Vector3d& v, Vec3* out) {
  out->set_x(v.x());
  out->set_y(v.y());
  out->set_z(v.z());
}

inline Vec3 to_wire(const Eigen::Vector3d& v) {
  Vec3 out;
  to_wire(v, &out);
  return out;
}

/// An absent Vec3 reads as zeros (proto3 defaults).
inline Eigen::Vector3d from_wire(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

inline bool is_finite(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

}  // namespace cohaptic::wire
