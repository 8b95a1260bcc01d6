// RemoteToolBuffer: a remote user's tool positions, played out at a controlled delay.
//
// Samples arrive stamped with the time the remote device was read, converted to the local
// clock. The haptic loop asks for the position at its own time `now` under a policy:
//   newest   the newest sample, however old;
//   fixed    the position at now - D, linearly interpolated between the samples around it
//            (the newest one held if it is older than that): smooth and of known latency;
//   adaptive as fixed, with D following the observed sample age (its 95th percentile over
//            the last second, plus 1 ms), so it grows with jitter and shrinks after it.
// Fixed capacity, no allocation after construction: safe in the haptic thread. Samples
// must be added in arrival order; out-of-order (older) ones are dropped and counted.
// Units: ns and m.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>

namespace cohaptic {

enum class PlayoutPolicy { newest, fixed, adaptive };

PlayoutPolicy parse_playout_policy(const std::string& text);  ///< throws Error
const char* to_string(PlayoutPolicy policy);

struct PlayoutQuery {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  bool valid = false;       ///< false before the first sample, or after an invalid one
  std::int64_t age_ns = 0;  ///< now minus the time of the position returned
};

class RemoteToolBuffer {
 public:
  static constexpr int kCapacity = 1024;  // about 1 s at 1 kHz

  RemoteToolBuffer(PlayoutPolicy policy, std::int64_t fixed_delay_ns) noexcept;

  /// A sample read at `sample_time_ns` and received at `arrival_ns` (both local clock).
  void add(std::int64_t sample_time_ns, std::int64_t arrival_ns, const Eigen::Vector3d& position,
           bool valid) noexcept;
  PlayoutQuery at(std::int64_t now_ns) const noexcept;

  std::int64_t playout_delay_ns() const noexcept;
  std::uint64_t dropped_out_of_order() const noexcept { return dropped_; }

 private:
  struct Sample {
    std::int64_t time = 0;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    bool valid = false;
  };
  const Sample& sample(int age) const noexcept {
    return samples_[static_cast<std::size_t>((head_ - 1 - age + kCapacity) % kCapacity)];
  }

  PlayoutPolicy policy_;
  std::int64_t fixed_delay_ns_;
  std::array<Sample, kCapacity> samples_{};
  int head_ = 0;  // next slot to write
  int count_ = 0;
  std::uint64_t dropped_ = 0;
  // Adaptive delay: ages at arrival over the last second, in 0.25 ms bins.
  static constexpr int kAgeBins = 800;  // up to 200 ms
  std::array<std::uint16_t, kAgeBins> age_histogram_{};
  std::array<std::int16_t, kCapacity> age_bin_of_slot_{};
  std::int64_t adaptive_delay_ns_ = 0;
};

}  // namespace cohaptic
