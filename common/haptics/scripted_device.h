// ScriptedDevice: a device that plays a Trajectory and ignores the force it is given, so
// that a run is repeatable whatever the tissue does (open-loop probing, benchmarks, demos).
//
// read(t) is the trajectory's position and buttons at t (valid); write_force()
// only keeps the last force and its time, for tests. finished(t) once t > duration().
// Units: m, N, s. Haptic-thread methods neither allocate nor lock.
#pragma once

#include <Eigen/Core>
#include <string>

#include "common/haptics/haptic_device.h"
#include "common/haptics/trajectory.h"

namespace cohaptic {

class ScriptedDevice : public HapticDevice {
 public:
  /// `force_limit` [N] > 0 (throws Error otherwise).
  ScriptedDevice(Trajectory trajectory, double force_limit);

  std::string describe() const override;
  DeviceState read(double time_s) override;
  void write_force(const Eigen::Vector3d& force, double time_s) override;
  double force_limit() const override { return force_limit_; }
  bool finished(double time_s) const override { return time_s > trajectory_.duration(); }

  const Trajectory& trajectory() const { return trajectory_; }
  /// The last force written [N] and when [s] (zero and -infinity before the first).
  const Eigen::Vector3d& last_force() const { return last_force_; }
  double last_force_time() const { return last_force_time_; }

 private:
  Trajectory trajectory_;
  double force_limit_;
  Eigen::Vector3d last_force_ = Eigen::Vector3d::Zero();
  double last_force_time_;
};

}  // namespace cohaptic
