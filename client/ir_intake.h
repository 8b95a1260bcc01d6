// IrIntake: the IRs the server sends, on the client's I/O thread. Each is taken out of its
// connection's zstd stream if it came compressed (proto/wire/ir_stream.h), converted from
// the wire, completed if it came as compliance rows (its M~ condensed here from the rows
// held, ClientCondensation), checked and prepared (prepare_ir: the factorisations the haptic loop
// needs, done here so the haptic thread never does them) with its fresh evaluation state, then
// handed to the haptic thread through its TripleBuffer with the time it arrived. A sphere IR's
// contact solve is first warmed to the tools' latest positions the I/O thread has seen
// (warm_start_sphere_contact.h), so that the haptic thread's first tick on it starts from where
// they are. An IR that fails its checks is counted and logged, and never reaches the haptic
// thread.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>

#include "cohaptic/messages.pb.h"
#include "cohaptic/recording.pb.h"
#include "client/haptic_loop.h"
#include "common/ir/client_condensation.h"
#include "common/kinds/session_limits.h"
#include "common/util/histogram.h"
#include "common/util/triple_buffer.h"
#include "proto/wire/ir_stream.h"

namespace cohaptic {

class IrIntake {
 public:
  explicit IrIntake(TripleBuffer<IrSlot>& to_haptic) : to_haptic_(to_haptic) {}

  /// Prepares and hands over `message` (`bytes` on the wire). False if it was rejected.
  bool receive(const wire::IntermediateRepresentation& message, std::size_t bytes,
               std::int64_t arrival_ns);
  /// Decompresses `block` in this connection's IR stream, then as receive(). Returns
  /// whether the stream opened it (the IR in it accepted or not): a recording keeps every
  /// block the stream opened, for the blocks after it. A new connection's stream starts at
  /// its first block.
  bool receive_compressed(const wire::CompressedIr& block, std::size_t bytes,
                          std::int64_t arrival_ns);

  /// The own tool's latest position as the haptic thread sent it, and a remote user's as it
  /// arrived: where the next sphere IR's contact solve is warmed to.
  void see_own_tool(const Eigen::Vector3d& position, bool valid);
  void see_remote_tool(std::uint32_t user, const Eigen::Vector3d& position, bool valid);
  /// The positions the IR last accepted was warmed to, for its recording; null if it was not.
  const record::WarmStart* warmed() const { return warmed_ ? &*warmed_ : nullptr; }

  /// The report's "ir": received, rejected, bytes, bytes_per_s (from the first IR to the
  /// last), and of those sent as compliance rows: condensed, condense_cpu_us_p50 and _max
  /// (the I/O thread's CPU for M~ per IR); of those that came compressed: inflated,
  /// inflate_cpu_us_p50 and _max (the I/O thread's CPU to decompress each).
  nlohmann::json report() const;

 private:
  /// Warms a sphere IR's contact solve to the tools' latest positions (warmed_ says where).
  void warm(PreparedIR& prepared);

  TripleBuffer<IrSlot>& to_haptic_;
  ClientCondensation condensation_;
  wire::IrStreamReader stream_;
  Histogram inflate_us_{5, 20000};  // CPU of decompressing each IR that came compressed [µs]
  Histogram condense_us_{
      5, 20000};  // CPU of completing each IR sent as compliance rows [µs], to 100 ms
  std::optional<Eigen::Vector3d> own_;
  std::array<std::optional<Eigen::Vector3d>, kMaxUsers> remotes_;  // per user slot
  std::optional<record::WarmStart> warmed_;
  std::uint64_t received_ = 0, rejected_ = 0, bytes_ = 0;
  std::int64_t first_ns_ = 0, last_ns_ = 0;
};

}  // namespace cohaptic
