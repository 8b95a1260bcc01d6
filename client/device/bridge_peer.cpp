#include "client/device/bridge_peer.h"

#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {

BridgePeer::BridgePeer(const std::string& client_host, std::uint16_t client_port) : socket_(io_) {
  asio::error_code ec;
  asio::ip::udp::resolver resolver(io_);
  const auto results =
      resolver.resolve(asio::ip::udp::v4(), client_host, std::to_string(client_port), ec);
  if (ec || results.empty()) {
    // Not an IPv4 name: try IPv6 before giving up.
    asio::error_code ec6;
    const auto results6 =
        resolver.resolve(asio::ip::udp::v6(), client_host, std::to_string(client_port), ec6);
    if (ec6 || results6.empty())
      throw Error(fmt::format("bridge peer: cannot resolve '{}': {}", client_host,
                              (ec ? ec : ec6).message()));
    client_ = results6.begin()->endpoint();
  } else {
    client_ = results.begin()->endpoint();
  }
  socket_.open(client_.protocol(), ec);
  if (!ec) socket_.bind(asio::ip::udp::endpoint(client_.protocol(), 0), ec);
  if (!ec) socket_.non_blocking(true, ec);
  if (ec) throw Error(fmt::format("bridge peer: cannot open a UDP socket: {}", ec.message()));
}

bool BridgePeer::send_pose(const Eigen::Vector3d& position, double device_time_s,
                           std::uint32_t buttons, bool valid) {
  bridge::PosePacket packet;
  packet.sequence = sequence_;
  packet.device_time_s = device_time_s;
  packet.position = position;
  packet.buttons = buttons;
  packet.flags = valid ? bridge::kPoseValid : 0u;
  ++sequence_;
  return send_pose(packet);
}

bool BridgePeer::send_pose(const bridge::PosePacket& packet) {
  bridge::PoseBytes bytes;
  bridge::encode(packet, bytes);
  return send_bytes(bytes);
}

bool BridgePeer::send_bytes(std::span<const std::uint8_t> bytes) {
  asio::error_code ec;
  socket_.send_to(asio::buffer(bytes.data(), bytes.size()), client_, 0, ec);
  if (ec) ++send_failed_;
  return !ec;
}

std::size_t BridgePeer::poll_forces() {
  std::size_t accepted = 0;
  for (;;) {
    asio::error_code ec;
    const std::size_t size = socket_.receive_from(asio::buffer(rx_), sender_, 0, ec);
    if (ec) break;  // would block (or an error: try again next poll)
    bridge::ForcePacket packet;
    if (sender_ != client_ ||
        bridge::decode(std::span<const std::uint8_t>(rx_.data(), size), packet) !=
            bridge::PacketStatus::ok ||
        (newest_force_ && bridge::sequence_after(newest_force_->sequence, packet.sequence))) {
      ++forces_dropped_;
      continue;
    }
    newest_force_ = packet;
    ++forces_received_;
    ++accepted;
  }
  return accepted;
}

std::uint16_t BridgePeer::local_port() const {
  asio::error_code ec;
  const auto endpoint = socket_.local_endpoint(ec);
  return ec ? std::uint16_t{0} : endpoint.port();
}

std::string BridgePeer::client() const {
  return fmt::format("{}:{}", client_.address().to_string(), client_.port());
}

}  // namespace cohaptic
