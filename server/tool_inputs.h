// ToolInputs: the newest tool sample of each user slot, the one piece of state the
// server's I/O thread and simulation thread share. The I/O thread (ConnectionHandler)
// writes a slot as its user joins, sends samples and leaves; the simulation thread
// (SimulationLoop) takes all of them once per step. A small mutex guards them: both
// sides hold it only to copy a few numbers. Units: m; ns of monotonic_now_ns().
// A step sees only the newest sample, so a button press is also counted as it arrives
// (`pressed`): one shorter than a step, or in a burst of samples a stalled link let through
// at once, is not lost.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <mutex>
#include <vector>

namespace cohaptic {

struct ToolInput {
  bool joined = false;  ///< a user holds the slot
  std::uint64_t joins =
      0;  ///< users that have taken the slot so far (a new one holds nothing of the last's)
  bool valid = false;  ///< the device reported a position
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::uint32_t buttons = 0;  ///< the device's buttons (bit i = button i)
  std::uint32_t pressed = 0;  ///< buttons that went down in a sample since the previous take()
  std::int64_t sample_time_ns = 0;  ///< the server's clock, as stamped by the client
  std::int64_t received_ns = 0;     ///< when the server took it in
};

class ToolInputs {
 public:
  explicit ToolInputs(std::size_t slots) : tools_(slots) {}

  /// A user took `slot`: no sample yet.
  void join(int slot);
  /// The user of `slot` left: its tool is released.
  void release(int slot);
  /// Takes a sample of `slot`'s tool; false (and nothing changes) if it is not newer than
  /// the one held, as a reordered datagram would be.
  bool update(int slot, bool valid, const Eigen::Vector3d& position, std::uint32_t buttons,
              std::int64_t sample_time_ns, std::int64_t received_ns);
  /// Copies every slot into `out` (resized to the number of slots) and starts counting
  /// presses afresh.
  void take(std::vector<ToolInput>& out);

  std::size_t size() const { return tools_.size(); }

 private:
  mutable std::mutex mutex_;
  std::vector<ToolInput> tools_;
};

}  // namespace cohaptic
