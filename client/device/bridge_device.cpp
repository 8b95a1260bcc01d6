#include "client/device/bridge_device.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {

static_assert(std::atomic<std::uint64_t>::is_always_lock_free,
              "the haptic thread's counters must be lock-free");

BridgeDevice::BridgeDevice(BridgeOptions options, double force_limit)
    : options_(std::move(options)), force_limit_(force_limit), socket_(io_) {
  if (!(options_.timeout_s > 0) || !std::isfinite(options_.timeout_s))
    throw Error(fmt::format("bridge device: expected a positive timeout in s, found {}",
                            options_.timeout_s));
  if (!(force_limit_ > 0) || !std::isfinite(force_limit_))
    throw Error(
        fmt::format("bridge device: expected a positive force limit in N, found {}", force_limit_));
  if (options_.max_packets_per_read < 1)
    throw Error(fmt::format("bridge device: expected at least 1 packet per read, found {}",
                            options_.max_packets_per_read));
}

BridgeDevice::~BridgeDevice() {
  asio::error_code ignored;
  socket_.close(ignored);
}

std::string BridgeDevice::describe() const {
  const std::uint16_t port = local_port() != 0 ? local_port() : options_.port;
  return fmt::format("bridge:{}:{} (timeout {} ms, force limit {} N)", options_.host, port,
                     options_.timeout_s * 1e3, force_limit_);
}

void BridgeDevice::start() {
  if (socket_.is_open()) return;
  asio::error_code ec;
  const asio::ip::address address = asio::ip::make_address(options_.host, ec);
  if (ec)
    throw Error(
        fmt::format("bridge device: '{}' is not an IP address: {}", options_.host, ec.message()));
  const asio::ip::udp::endpoint endpoint(address, options_.port);
  socket_.open(endpoint.protocol(), ec);
  if (!ec) socket_.bind(endpoint, ec);
  if (!ec) socket_.non_blocking(true, ec);
  if (ec) {
    asio::error_code ignored;
    socket_.close(ignored);
    throw Error(fmt::format("bridge device: cannot listen on udp {}:{}: {}", options_.host,
                            options_.port, ec.message()));
  }
  local_port_.store(socket_.local_endpoint().port(), std::memory_order_relaxed);
  spdlog::info("bridge device: listening on udp {}:{} for pose packets (timeout {} ms)",
               options_.host, local_port(), options_.timeout_s * 1e3);
}

void BridgeDevice::stop() {
  if (!socket_.is_open()) return;
  const BridgeCounters c = counters();
  spdlog::info(
      "bridge device: stopped; program {}; {} datagrams, {} poses accepted, dropped {} (size {}, "
      "magic {}, non-finite {}, "
      "foreign {}, stale {}), {} receive errors, {} forces sent, {} not sent",
      has_peer() ? peer() : "never heard", c.received, c.accepted, c.dropped(), c.bad_size,
      c.bad_magic, c.non_finite, c.foreign_source, c.stale, c.receive_errors, c.forces_sent,
      c.send_failed);
  asio::error_code ignored;
  socket_.close(ignored);
}

void BridgeDevice::take(std::size_t size, double time_s, bool& timed_out) {
  bump(counters_.received);
  const bool known = has_peer_.load(std::memory_order_relaxed);
  if (known && sender_ != peer_) {
    bump(counters_.foreign_source);
    return;
  }
  bridge::PosePacket packet;
  switch (bridge::decode(std::span<const std::uint8_t>(rx_.data(), size), packet)) {
    case bridge::PacketStatus::ok:
      break;
    case bridge::PacketStatus::bad_size:
      bump(counters_.bad_size);
      return;
    case bridge::PacketStatus::bad_magic:
      bump(counters_.bad_magic);
      return;
    case bridge::PacketStatus::non_finite:
      bump(counters_.non_finite);
      return;
  }
  if (!known) {
    peer_ = sender_;
    has_peer_.store(true, std::memory_order_release);
  }
  if (have_pose_ && !timed_out && !bridge::sequence_after(packet.sequence, newest_.sequence)) {
    bump(counters_.stale);
    return;
  }
  newest_ = packet;
  have_pose_ = true;
  timed_out = false;
  last_accept_time_s_ = time_s;
  bump(counters_.accepted);
}

DeviceState BridgeDevice::read(double time_s) {
  if (socket_.is_open()) {
    bool timed_out = !have_pose_ || time_s - last_accept_time_s_ > options_.timeout_s;
    for (int i = 0; i < options_.max_packets_per_read; ++i) {
      asio::error_code ec;
      const std::size_t size = socket_.receive_from(asio::buffer(rx_), sender_, 0, ec);
      if (ec) {
        if (ec != asio::error::would_block && ec != asio::error::try_again)
          bump(counters_.receive_errors);
        break;
      }
      take(size, time_s, timed_out);
    }
  }
  DeviceState state;
  const bool fresh = have_pose_ && time_s - last_accept_time_s_ <= options_.timeout_s;
  if (fresh && (newest_.flags & bridge::kPoseValid) != 0) last_valid_position_ = newest_.position;
  state.valid = fresh && (newest_.flags & bridge::kPoseValid) != 0;
  state.position = last_valid_position_;
  state.buttons = fresh ? newest_.buttons : 0;
  valid_now_ = state.valid;
  return state;
}

void BridgeDevice::write_force(const Eigen::Vector3d& force, double /*time_s*/) {
  if (!socket_.is_open() || !has_peer_.load(std::memory_order_relaxed)) return;
  bridge::ForcePacket packet;
  packet.sequence = newest_.sequence;
  packet.device_time_s = newest_.device_time_s;
  const bool finite = force.allFinite();
  packet.force = finite ? force : Eigen::Vector3d::Zero();
  packet.force_limit = force_limit_;
  packet.flags = valid_now_ && finite ? bridge::kClientValid : 0u;
  bridge::encode(packet, tx_);
  asio::error_code ec;
  socket_.send_to(asio::buffer(tx_), peer_, 0, ec);
  bump(ec ? counters_.send_failed : counters_.forces_sent);
}

BridgeCounters BridgeDevice::counters() const {
  BridgeCounters c;
  const auto get = [](const std::atomic<std::uint64_t>& a) {
    return a.load(std::memory_order_relaxed);
  };
  c.received = get(counters_.received);
  c.accepted = get(counters_.accepted);
  c.bad_size = get(counters_.bad_size);
  c.bad_magic = get(counters_.bad_magic);
  c.non_finite = get(counters_.non_finite);
  c.foreign_source = get(counters_.foreign_source);
  c.stale = get(counters_.stale);
  c.receive_errors = get(counters_.receive_errors);
  c.forces_sent = get(counters_.forces_sent);
  c.send_failed = get(counters_.send_failed);
  return c;
}

std::string BridgeDevice::peer() const {
  if (!has_peer()) return "";
  return fmt::format("{}:{}", peer_.address().to_string(), peer_.port());
}

}  // namespace cohaptic
