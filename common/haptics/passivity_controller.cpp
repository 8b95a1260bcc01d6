#include "common/haptics/passivity_controller.h"

#include <cmath>

namespace cohaptic {

Eigen::Vector3d PassivityController::limited(const Eigen::Vector3d& force) const {
  const double magnitude = force.norm();
  return magnitude > force_limit_ ? Eigen::Vector3d(force * (force_limit_ / magnitude)) : force;
}

Eigen::Vector3d PassivityController::filter(double time_s, const Eigen::Vector3d& position,
                                            const Eigen::Vector3d& environment_force) {
  const Eigen::Vector3d environment = limited(environment_force);
  if (!started_ || !(time_s > last_time_) || !position.allFinite()) {
    started_ = position.allFinite();
    last_time_ = time_s;
    if (started_) last_position_ = position;
    last_output_ = environment;
    last_damping_.setZero();
    return environment;
  }
  const double period = time_s - last_time_;
  const Eigen::Vector3d step = position - last_position_;
  // The force held over the last interval did work last_output . step on the hand; the
  // damping part of it dissipated -last_damping . step.
  energy_ -= last_output_.dot(step);
  dissipated_ -= last_damping_.dot(step);
  Eigen::Vector3d output = environment;
  const double speed_squared = step.squaredNorm() / (period * period);
  if (energy_ < -energy_tolerance_ && speed_squared > 0) {
    // A damper b applied for one period T changes the velocity of a mass m by at most the
    // fraction b T / m: kept at 1/2, it cannot reverse the hand by itself.
    const double alpha = std::min(-(energy_ + energy_tolerance_) / (period * speed_squared),
                                  0.5 * moving_mass_ / period);
    output = limited(environment - alpha * step / period);
    ++active_ticks_;
  }
  last_damping_ = output - environment;
  last_time_ = time_s;
  last_position_ = position;
  last_output_ = output;
  return output;
}

}  // namespace cohaptic
