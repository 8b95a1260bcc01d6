// HapticDevice: what a haptic loop needs of a device: the client's real-time loop
// (client/haptic_loop.h), or an offline simulation of one (lab/stability.h). The devices
// that are pure computation live beside it (scripted_device.h, hand_model.h); those with
// sockets or files of a session, and their command-line names, in client/device/.
//
// The loop calls read() then write_force() once per tick, from the haptic thread only. An
// implementation must return in bounded time and must not allocate or take a lock there
// (a system call of its own, such as a non-blocking socket read, is allowed). start() and
// stop() run outside the loop and may do anything. Units: m, N, s; positions in the
// scene's frame; time_s counts from the loop's start.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>

namespace cohaptic {

struct DeviceState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< tool point [m]
  std::uint32_t buttons = 0;
  bool valid = true;  ///< false: no pose this tick (e.g. a bridge whose program went silent)
};

class HapticDevice {
 public:
  virtual ~HapticDevice() = default;

  /// One line for logs and reports, e.g. "script:scenes/brain_a.yaml".
  virtual std::string describe() const = 0;
  /// Before the loop: open sockets, load files. May block and allocate.
  virtual void start() {}
  /// The pose now. Haptic thread; no allocation, no lock.
  virtual DeviceState read(double time_s) = 0;
  /// The force to render, already limited by the loop [N]. Haptic thread.
  virtual void write_force(const Eigen::Vector3d& force, double time_s) = 0;
  /// The largest force the device can render [N].
  virtual double force_limit() const = 0;
  /// A scripted device whose script has ended; live devices never finish.
  virtual bool finished(double /*time_s*/) const { return false; }
  /// After the loop.
  virtual void stop() {}
};

}  // namespace cohaptic
