// HandModelDevice: a closed-loop stand-in for a user's hand. An arm of mass m is pulled
// towards a scripted reference r(t) (a Trajectory) by a spring k and a damper c, and the
// force F the haptic loop renders acts on it, so what it feels changes how it moves:
//
//     m x'' = k (r(t) - x) + c (r'(t) - x') + F
//
// This is the case where a rendering instability shows (a stiff contact against a light,
// lightly damped arm), which an open-loop ScriptedDevice can never reveal.
//
// Integration: semi-implicit (symplectic) Euler, v += h a(x, v, t); x += h v, with the
// reference and F held over each sub-step (F is zero-order held from write_force() to the
// next read()). read(t) advances the state from the last read to t in equal sub-steps of at
// most max_substep_s (<= 0.1 ms) and returns x. At most kMaxSubstepsPerRead sub-steps run
// per read (0.5 s of model time at 0.1 ms); a longer gap (a stalled host) freezes the arm
// for the rest and is counted in skipped_time_s(). Time that goes backwards is ignored.
// The state starts at rest on the reference: x(0) = r(0), x'(0) = 0.
//
// Default parameters, m = 0.2 kg, k = 300 N/m, c = 8 N s/m, stand for a relaxed hand holding
// a pen-like stylus, chosen by reasoning rather than fitted to any measurement: 0.2 kg is
// the part of the hand, fingers and stylus that moves with the tool tip when the wrist and
// fingers are compliant (a whole hand is about 0.4 kg); sqrt(k/m) = 38.7 rad/s (6.2 Hz)
// puts the arm's natural frequency inside the band of voluntary hand motion (up to about
// 10 Hz) and below physiological tremor (8-12 Hz); c gives a damping ratio c / (2 sqrt(k m)) =
// 0.52, a moderately damped, not stiffened, grip. Published fingertip and wrist impedance
// identifications span roughly an order of magnitude around these values; change them in
// the file's `hand:` map (SI: mass [kg], stiffness [N/m], damping [N s/m]).
//
// Units: m, N, s, kg. Invariants: mass > 0, stiffness > 0, damping >= 0, and the sub-step
// resolves the arm: h sqrt(k/m) <= 0.5 and h c / m <= 0.5 (checked, Error otherwise).
// Haptic-thread methods neither allocate nor lock.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "common/haptics/haptic_device.h"
#include "common/haptics/trajectory.h"

namespace cohaptic {

struct HandParameters {
  double mass_kg = 0.2;
  double stiffness_n_per_m = 300.0;
  double damping_ns_per_m = 8.0;
};

/// Integrator state: model time [s], tool position [m], velocity [m/s].
struct HandState {
  double time_s = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
};

class HandModelDevice : public HapticDevice {
 public:
  static constexpr double kDefaultMaxSubstep = 1e-4;  ///< [s]
  static constexpr std::int64_t kMaxSubstepsPerRead = 5000;

  /// Throws Error for invalid parameters, force limit <= 0, or max_substep_s outside (0, 1e-4].
  HandModelDevice(Trajectory reference, HandParameters parameters, double force_limit,
                  double max_substep_s = kDefaultMaxSubstep);

  std::string describe() const override;
  /// Advances the arm to time_s and returns its position (always valid) and the script's buttons.
  DeviceState read(double time_s) override;
  /// The force on the arm from now until the next read [N]; a non-finite force counts as zero.
  void write_force(const Eigen::Vector3d& force, double time_s) override;
  double force_limit() const override { return force_limit_; }
  /// The reference has ended (the arm itself may still be settling).
  bool finished(double time_s) const override { return time_s > reference_.duration(); }

  /// Integrates from state().time_s to time_s (what read() does, without returning a state).
  void advance_to(double time_s);

  const HandState& state() const { return state_; }
  void set_state(const HandState& state) { state_ = state; }
  const Eigen::Vector3d& applied_force() const { return force_; }
  const HandParameters& parameters() const { return parameters_; }
  const Trajectory& reference() const { return reference_; }
  double max_substep() const { return max_substep_; }
  std::uint64_t substep_count() const { return substeps_; }
  double skipped_time_s() const { return skipped_s_; }
  std::uint64_t non_finite_forces() const { return non_finite_forces_; }

 private:
  Trajectory reference_;
  HandParameters parameters_;
  double force_limit_;
  double max_substep_;
  HandState state_;
  Eigen::Vector3d force_ = Eigen::Vector3d::Zero();
  std::uint64_t substeps_ = 0;
  double skipped_s_ = 0.0;
  std::uint64_t non_finite_forces_ = 0;
};

/// Throws Error naming the bad field if the parameters are not physical (see invariants).
void validate_hand_parameters(const HandParameters& parameters);

/// The optional `hand:` map of a trajectory file ({mass, stiffness, damping}, SI; each key
/// optional, defaults above); nothing if the file has no `hand:`. Only `hand:` is read.
/// Errors are ParseErrors naming the file, line and key.
std::optional<HandParameters> parse_hand_parameters(const std::string& yaml,
                                                    const std::string& name);
std::optional<HandParameters> load_hand_parameters(const std::filesystem::path& file);

}  // namespace cohaptic
