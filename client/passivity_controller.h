// PassivityController: a time-domain passivity observer and controller (Hannaford and Ryu,
// 2002) at the haptic device's port, the option that keeps a sampled, delayed or stepwise
// rendering passive for any hand.
//
// Each tick k (period T) it observes the energy the virtual environment has absorbed from
// the hand so far,
//     W(k) = W(k-1) - F(k-1) . (x(k) - x(k-1)),
// F the force it output to the hand over the last interval and x the tool position. A
// passive environment keeps W >= 0. When W < -E_tol (the environment has given out more
// than it took, as a delayed or held force does), it adds to the environment's force a
// damping force -alpha v, v = (x(k) - x(k-1)) / T, alpha = -(W + E_tol) / (T |v|^2): if the
// hand keeps its velocity, the damper dissipates over the coming interval what was created
// beyond the tolerance (the next observation books what it really did, damping included),
// so W stays above about -E_tol. When all is well (W >= -E_tol)
// it changes nothing: its cost in transparency is the damping it adds after energy has
// been created. Two guards keep the damper itself harmless:
//   - alpha is capped at m / (2 T), m = `moving_mass` [kg] the lightest mass expected at
//     the tool (hand, fingers, stylus): a larger damper, applied with last tick's velocity,
//     could reverse the hand within one tick and then push it along (the chattering a
//     one-step-late damper is known for); the deficit is then paid over several ticks;
//   - it acts only on the deficit beyond E_tol = `energy_tolerance` [J]: a zero-order-held
//     spring gives back some microjoules on every release, and damping that away would
//     make the wall feel sticky (and jolt) for nothing.
// Units: m, N, s, J. Allocation- and lock-free (haptic thread).
#pragma once

#include <Eigen/Core>

namespace cohaptic {

class PassivityController {
 public:
  explicit PassivityController(double moving_mass = 0.2, double energy_tolerance = 1e-4)
      : moving_mass_(moving_mass), energy_tolerance_(energy_tolerance) {}

  /// The force to output at tick time `time_s` with the tool at `position`, given the
  /// environment's force `environment_force`. Call once per tick, in time order.
  Eigen::Vector3d filter(double time_s, const Eigen::Vector3d& position, const Eigen::Vector3d& environment_force);

  /// Energy the environment (with the damper) has absorbed from the hand, as observed [J].
  double observed_energy() const { return energy_; }
  /// Energy the controller's damping has dissipated so far [J].
  double dissipated_energy() const { return dissipated_; }
  /// Ticks on which the controller acted.
  long active_ticks() const { return active_ticks_; }

 private:
  double moving_mass_;
  double energy_tolerance_;
  bool started_ = false;
  double last_time_ = 0;
  Eigen::Vector3d last_position_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_output_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_damping_ = Eigen::Vector3d::Zero();
  double energy_ = 0, dissipated_ = 0;
  long active_ticks_ = 0;
};

}  // namespace cohaptic
