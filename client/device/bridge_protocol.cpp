#include "client/device/bridge_protocol.h"

#include <bit>
#include <cmath>
#include <cstring>

namespace cohaptic::bridge {
namespace {

void put_u32(std::uint8_t* at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) at[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put_f64(std::uint8_t* at, double d) {
  const auto v = std::bit_cast<std::uint64_t>(d);
  for (int i = 0; i < 8; ++i) at[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
std::uint32_t get_u32(const std::uint8_t* at) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(at[i]) << (8 * i);
  return v;
}
double get_f64(const std::uint8_t* at) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(at[i]) << (8 * i);
  return std::bit_cast<double>(v);
}

}  // namespace

std::string_view to_string(PacketStatus status) {
  switch (status) {
    case PacketStatus::ok:
      return "ok";
    case PacketStatus::bad_size:
      return "bad size";
    case PacketStatus::bad_magic:
      return "bad magic";
    case PacketStatus::non_finite:
      return "non-finite value";
  }
  return "?";
}

void encode(const PosePacket& p, PoseBytes& out) {
  std::uint8_t* b = out.data();
  std::memcpy(b, kPoseMagic.data(), 4);
  put_u32(b + 4, p.sequence);
  put_f64(b + 8, p.device_time_s);
  put_f64(b + 16, p.position.x());
  put_f64(b + 24, p.position.y());
  put_f64(b + 32, p.position.z());
  put_u32(b + 40, p.buttons);
  put_u32(b + 44, p.flags);
}

void encode(const ForcePacket& p, ForceBytes& out) {
  std::uint8_t* b = out.data();
  std::memcpy(b, kForceMagic.data(), 4);
  put_u32(b + 4, p.sequence);
  put_f64(b + 8, p.device_time_s);
  put_f64(b + 16, p.force.x());
  put_f64(b + 24, p.force.y());
  put_f64(b + 32, p.force.z());
  put_f64(b + 40, p.force_limit);
  put_u32(b + 48, p.flags);
  put_u32(b + 52, 0);
}

PacketStatus decode(std::span<const std::uint8_t> bytes, PosePacket& out) {
  if (bytes.size() != kPosePacketSize) return PacketStatus::bad_size;
  const std::uint8_t* b = bytes.data();
  if (std::memcmp(b, kPoseMagic.data(), 4) != 0) return PacketStatus::bad_magic;
  out.sequence = get_u32(b + 4);
  out.device_time_s = get_f64(b + 8);
  out.position = Eigen::Vector3d(get_f64(b + 16), get_f64(b + 24), get_f64(b + 32));
  out.buttons = get_u32(b + 40);
  out.flags = get_u32(b + 44);
  if (!std::isfinite(out.device_time_s) || !out.position.allFinite())
    return PacketStatus::non_finite;
  return PacketStatus::ok;
}

PacketStatus decode(std::span<const std::uint8_t> bytes, ForcePacket& out) {
  if (bytes.size() != kForcePacketSize) return PacketStatus::bad_size;
  const std::uint8_t* b = bytes.data();
  if (std::memcmp(b, kForceMagic.data(), 4) != 0) return PacketStatus::bad_magic;
  out.sequence = get_u32(b + 4);
  out.device_time_s = get_f64(b + 8);
  out.force = Eigen::Vector3d(get_f64(b + 16), get_f64(b + 24), get_f64(b + 32));
  out.force_limit = get_f64(b + 40);
  out.flags = get_u32(b + 48);
  if (!std::isfinite(out.device_time_s) || !out.force.allFinite() ||
      !std::isfinite(out.force_limit))
    return PacketStatus::non_finite;
  return PacketStatus::ok;
}

}  // namespace cohaptic::bridge
