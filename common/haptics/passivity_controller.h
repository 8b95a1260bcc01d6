// PassivityController: a time-domain passivity observer and controller (Hannaford and Ryu,
// 2002) at the haptic device's port, the option that keeps a sampled, delayed or stepwise
// rendering passive for the hand.
//
// Each tick k (period T) it observes the energy the virtual environment has absorbed from
// the hand so far,
//     W(k) = W(k-1) - F(k-1) . (x(k) - x(k-1)),
// F the force it output (and the device received) over the last interval and x the tool
// position. A passive environment keeps W >= 0. When W < -E_tol (the environment has given
// out more than it took, as a delayed or held force does), it adds to the environment's
// force a damping force -alpha v, v = (x(k) - x(k-1)) / T, alpha = -(W + E_tol) / (T |v|^2):
// if the hand keeps its velocity, the damper dissipates over the coming interval what was
// created beyond the tolerance. The next observation books what the output really did,
// damping included, so W stays above about -E_tol. When all is well (W >= -E_tol) it changes
// nothing: its cost in transparency is the damping it adds after energy has been created.
//
// The output is limited to `force_limit` here, not after: the force it books must be the
// force the device received, or a clamp would hide energy from the observer. Two guards
// keep the damper in check:
//   - alpha is capped at m / (2 T), m = `moving_mass` [kg] the lightest mass expected at
//     the tool (hand, fingers, stylus): a larger damper, applied with last tick's velocity,
//     could reverse the hand within one tick and then push it along (the chattering a
//     one-step-late damper is known for); the deficit is then paid over several ticks.
//     When the hand reverses on its own the damper still pushes along its new motion for
//     one tick; the observer books that too, so the total stays bounded;
//   - it acts only on the deficit beyond E_tol = `energy_tolerance` [J]: a zero-order-held
//     spring gives back some microjoules on every release, and damping that away would
//     make the wall feel sticky (and jolt) for nothing.
// Units: m, N, s, J. Allocation- and lock-free (haptic thread).
#pragma once

#include <Eigen/Core>
#include <limits>

namespace cohaptic {

class PassivityController {
 public:
  explicit PassivityController(double moving_mass = 0.2,
                               double force_limit = std::numeric_limits<double>::infinity(),
                               double energy_tolerance = 1e-4)
      : moving_mass_(moving_mass), force_limit_(force_limit), energy_tolerance_(energy_tolerance) {}

  /// The force to output at tick time `time_s` with the tool at `position`, given the
  /// environment's force `environment_force`, limited to the force limit. Call once per
  /// tick, in time order, and write exactly what it returns.
  Eigen::Vector3d filter(double time_s, const Eigen::Vector3d& position,
                         const Eigen::Vector3d& environment_force);

  /// No force was output since the last filter() (the device was not valid): the next
  /// filter() starts a new interval. The energy observed so far is kept.
  void interrupt() { started_ = false; }

  /// Energy the environment (with the damper) has absorbed from the hand, as observed [J].
  double observed_energy() const { return energy_; }
  /// Energy the controller's damping has dissipated so far [J].
  double dissipated_energy() const { return dissipated_; }
  /// Ticks on which the controller acted.
  long active_ticks() const { return active_ticks_; }

 private:
  Eigen::Vector3d limited(const Eigen::Vector3d& force) const;

  double moving_mass_;
  double force_limit_;
  double energy_tolerance_;
  bool started_ = false;
  double last_time_ = 0;
  Eigen::Vector3d last_position_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_output_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_damping_ =
      Eigen::Vector3d::Zero();  // output minus the limited environment force
  double energy_ = 0, dissipated_ = 0;
  long active_ticks_ = 0;
};

}  // namespace cohaptic
