#include "server/tool_inputs.h"

namespace cohaptic {

void ToolInputs::join(int slot) {
  std::lock_guard lock(mutex_);
  ToolInput& tool = tools_[static_cast<std::size_t>(slot)];
  tool = ToolInput{.joined = true, .joins = tool.joins + 1};
}

void ToolInputs::release(int slot) {
  std::lock_guard lock(mutex_);
  ToolInput& tool = tools_[static_cast<std::size_t>(slot)];
  tool = ToolInput{
      .joins = tool.joins};  // still counted: a leave and a join between two steps is a new user
}

bool ToolInputs::update(int slot, bool valid, const Eigen::Vector3d& position,
                        std::uint32_t buttons, std::int64_t sample_time_ns,
                        std::int64_t received_ns) {
  std::lock_guard lock(mutex_);
  ToolInput& tool = tools_[static_cast<std::size_t>(slot)];
  if (sample_time_ns <= tool.sample_time_ns) return false;
  tool.valid = valid;
  tool.position = position;
  tool.pressed |= buttons & ~tool.buttons;
  tool.buttons = buttons;
  tool.sample_time_ns = sample_time_ns;
  tool.received_ns = received_ns;
  return true;
}

void ToolInputs::take(std::vector<ToolInput>& out) {
  std::lock_guard lock(mutex_);
  out = tools_;
  for (ToolInput& tool : tools_) tool.pressed = 0;
}

}  // namespace cohaptic
