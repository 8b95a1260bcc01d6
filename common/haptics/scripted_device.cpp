#include "common/haptics/scripted_device.h"

#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "common/util/error.h"

namespace cohaptic {

ScriptedDevice::ScriptedDevice(Trajectory trajectory, double force_limit)
    : trajectory_(std::move(trajectory)),
      force_limit_(force_limit),
      last_force_time_(-std::numeric_limits<double>::infinity()) {
  if (!(force_limit_ > 0) || !std::isfinite(force_limit_))
    throw Error(fmt::format("scripted device {}: expected a positive force limit in N, found {}",
                            trajectory_.source(), force_limit_));
}

std::string ScriptedDevice::describe() const {
  return fmt::format("script:{} ({:.3f} s, force limit {} N)", trajectory_.source(),
                     trajectory_.duration(), force_limit_);
}

DeviceState ScriptedDevice::read(double time_s) {
  DeviceState state;
  state.position = trajectory_.position(time_s);
  state.buttons = trajectory_.buttons(time_s);
  state.valid = true;
  return state;
}

void ScriptedDevice::write_force(const Eigen::Vector3d& force, double time_s) {
  last_force_ = force;
  last_force_time_ = time_s;
}

}  // namespace cohaptic
