// The external-device bridge protocol (BRIDGE.md): the fixed-size little-endian UDP
// packets by which a program built on a vendor SDK is the client's haptic device.
//
// Pose packet, program -> client, 48 bytes:
//   off size type  field
//     0    4 char  magic "CHB1"
//     4    4 u32   sequence        increases by one per packet (wraps modulo 2^32)
//     8    8 f64   device_time_s   the program's own clock [s] (echoed back; never compared)
//    16    8 f64   x               tool position in the scene frame [m]
//    24    8 f64   y
//    32    8 f64   z
//    40    4 u32   buttons         bit i = button i pressed
//    44    4 u32   flags           bit 0 = pose valid; other bits 0 (ignored on receipt)
// Force packet, client -> program (to the address the poses come from), 56 bytes:
//     0    4 char  magic "CHF1"
//     4    4 u32   sequence        of the newest pose accepted when the force was computed
//     8    8 f64   device_time_s   that pose's device_time_s, echoed (round trip = now - it)
//    16    8 f64   fx              force to render on the hand [N], already limited
//    24    8 f64   fy
//    32    8 f64   fz
//    40    8 f64   force_limit     the client's force limit [N]
//    48    4 u32   flags           bit 0 = the client had a valid pose this tick; others 0
//    52    4 u32   reserved        0
// Integers are unsigned little-endian, reals IEEE-754 binary64 little-endian, whatever
// the host's byte order. A packet whose size or magic is wrong, or with a non-finite real,
// is rejected whole. Encoding and decoding neither allocate nor lock.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace cohaptic::bridge {

inline constexpr std::size_t kPosePacketSize = 48;
inline constexpr std::size_t kForcePacketSize = 56;
inline constexpr std::array<std::uint8_t, 4> kPoseMagic{'C', 'H', 'B', '1'};
inline constexpr std::array<std::uint8_t, 4> kForceMagic{'C', 'H', 'F', '1'};
inline constexpr std::uint32_t kPoseValid = 1u << 0;    ///< PosePacket::flags
inline constexpr std::uint32_t kClientValid = 1u << 0;  ///< ForcePacket::flags

struct PosePacket {
  std::uint32_t sequence = 0;
  double device_time_s = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< [m]
  std::uint32_t buttons = 0;
  std::uint32_t flags = kPoseValid;
};

struct ForcePacket {
  std::uint32_t sequence = 0;
  double device_time_s = 0.0;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< [N]
  double force_limit = 0.0;                         ///< [N]
  std::uint32_t flags = 0;
};

enum class PacketStatus { ok, bad_size, bad_magic, non_finite };
std::string_view to_string(PacketStatus status);

using PoseBytes = std::array<std::uint8_t, kPosePacketSize>;
using ForceBytes = std::array<std::uint8_t, kForcePacketSize>;

void encode(const PosePacket& packet, PoseBytes& out);
void encode(const ForcePacket& packet, ForceBytes& out);
/// Decodes `bytes` into `out` if the status is ok; leaves `out` unspecified otherwise.
PacketStatus decode(std::span<const std::uint8_t> bytes, PosePacket& out);
PacketStatus decode(std::span<const std::uint8_t> bytes, ForcePacket& out);

/// True if `a` comes after `b` in sequence order, modulo 2^32 (serial-number arithmetic).
inline bool sequence_after(std::uint32_t a, std::uint32_t b) {
  return a != b && static_cast<std::uint32_t>(a - b) < 0x80000000u;
}

}  // namespace cohaptic::bridge
