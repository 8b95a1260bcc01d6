#include "net/datagram_endpoint.h"

#include <algorithm>
#include <span>

#include "proto/wire/header.h"

namespace cohaptic::net {

using asio::ip::udp;

DatagramEndpoint::DatagramEndpoint(asio::io_context& io, const udp::endpoint& local,
                                   std::unique_ptr<wire::DatagramInspector> inspector, RateLimit limit)
    : socket_(io), inspector_(std::move(inspector)), limiter_(limit) {
  socket_.open(local.protocol());
  socket_.bind(local);
  std::error_code ignored;  // a smaller queue is still a queue
  socket_.set_option(asio::socket_base::receive_buffer_size(kReceiveBufferBytes), ignored);
  socket_.non_blocking(true);  // the drain after each wake-up must not wait
  port_ = socket_.local_endpoint().port();
}

void DatagramEndpoint::start(Handler on_datagram) {
  on_datagram_ = std::move(on_datagram);
  receive_next();
}

void DatagramEndpoint::receive_next() {
  socket_.async_receive_from(asio::buffer(buffer_), from_, [this](std::error_code error, std::size_t n) {
    if (error == asio::error::operation_aborted) return;  // closed
    // Other errors (an ICMP "port unreachable" for an earlier send, say) concern no one
    // datagram: keep receiving.
    if (!error) take(n);
    for (int read = 1; read < kReadsPerWakeUp && socket_.is_open(); ++read) {
      n = socket_.receive_from(asio::buffer(buffer_), from_, 0, error);
      if (error == asio::error::would_block) break;
      if (!error) take(n);
    }
    if (socket_.is_open()) receive_next();
  });
}

void DatagramEndpoint::take(std::size_t bytes) {
  const std::int64_t arrival = wire::monotonic_now_ns();
  const bool admitted = trusted(from_);
  if (!admitted && limiter_.limited(from_.address(), arrival)) {
    inspector_->count_unread(wire::Rejection::rate_limited);
    return;
  }
  if (std::optional<wire::Datagram> datagram = inspector_->inspect(std::span(buffer_.data(), bytes)))
    on_datagram_(std::move(*datagram), from_, arrival);
  else if (!admitted)
    limiter_.charge(from_.address(), arrival);
}

bool DatagramEndpoint::trusted(const udp::endpoint& peer) const {
  return std::find(trusted_.begin(), trusted_.end(), peer) != trusted_.end();
}

void DatagramEndpoint::trust(const udp::endpoint& peer) {
  if (!trusted(peer)) trusted_.push_back(peer);
}

void DatagramEndpoint::distrust(const udp::endpoint& peer) { std::erase(trusted_, peer); }

void DatagramEndpoint::send(std::vector<std::uint8_t> datagram, const udp::endpoint& to) {
  auto bytes = std::make_shared<std::vector<std::uint8_t>>(std::move(datagram));
  socket_.async_send_to(asio::buffer(*bytes), to, [bytes, sent = sent_](std::error_code error, std::size_t) {
    if (!error) sent->fetch_add(1, std::memory_order_relaxed);
  });
}

void DatagramEndpoint::close() {
  std::error_code ignored;
  socket_.close(ignored);
}

}  // namespace cohaptic::net
