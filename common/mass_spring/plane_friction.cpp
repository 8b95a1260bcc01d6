#include "common/mass_spring/plane_friction.h"

namespace cohaptic {

Eigen::Vector3d plane_reaction(const SupportPlane& plane, const Eigen::Vector3d& x,
                               const Eigen::Vector3d& v, const Eigen::Vector3d& force, double mass,
                               double h, bool& sliding) noexcept {
  sliding = false;
  const Eigen::Vector3d& n = plane.normal;
  const double pressing = force.dot(n);
  if (height_above(plane, x) > kPlaneTouchTolerance || pressing > 0) return Eigen::Vector3d::Zero();
  const double normal_load = -pressing;
  const Eigen::Vector3d normal_force = normal_load * n;
  const Eigen::Vector3d v_t = v - v.dot(n) * n;
  const Eigen::Vector3d f_t = force - pressing * n;
  const Eigen::Vector3d stop = -(f_t + mass / h * v_t);
  const double speed = v_t.norm();
  // A sliding node feels mu_d until it stops; mu_s holds only a node at rest.
  const double holding = (speed > 0 ? plane.dynamic_friction : plane.static_friction) * normal_load;
  if (stop.norm() <= holding) return normal_force + stop;
  if (speed > 0) {
    sliding = true;
    return normal_force - plane.dynamic_friction * normal_load * v_t / speed;
  }
  const double pull = f_t.norm();
  return normal_force - plane.static_friction * normal_load * f_t / pull;
}

void settle_on_plane(const SupportPlane& plane, const Eigen::Vector3d& v_before, bool sliding,
                     Eigen::Ref<Eigen::Vector3d> v) noexcept {
  const Eigen::Vector3d& n = plane.normal;
  const double into = v.dot(n);
  if (into < 0) v -= into * n;
  if (sliding) {
    const Eigen::Vector3d before_t = v_before - v_before.dot(n) * n;
    const Eigen::Vector3d after_t = v - v.dot(n) * n;
    if (after_t.dot(before_t) < 0) v -= after_t;
  }
}

void keep_above(const SupportPlane& plane, Eigen::Ref<Eigen::Vector3d> x,
                Eigen::Ref<Eigen::Vector3d> v) noexcept {
  const double height = height_above(plane, x);
  if (height >= 0) return;
  x -= height * plane.normal;
  const double into = v.dot(plane.normal);
  if (into < 0) v -= into * plane.normal;
}

}  // namespace cohaptic
