#include "net/datagram_endpoint.h"

#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <span>

#include "common/util/monotonic_clock.h"
#include "proto/wire/header.h"

namespace cohaptic::net {

using asio::ip::udp;

DatagramEndpoint::DatagramEndpoint(asio::io_context& io, const udp::endpoint& local,
                                   std::unique_ptr<wire::DatagramInspector> inspector,
                                   RateLimit limit)
    : socket_(io), inspector_(std::move(inspector)), limiter_(limit) {
  socket_.open(local.protocol());
  socket_.bind(local);
  std::error_code ignored;  // a smaller queue is still a queue
  socket_.set_option(asio::socket_base::receive_buffer_size(kReceiveBufferBytes), ignored);
  socket_.non_blocking(true);  // the drain after each wake-up must not wait
  const int on = 1;            // each datagram read carries the socket's count of kernel drops
  ::setsockopt(socket_.native_handle(), SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on);
  port_ = socket_.local_endpoint().port();
}

void DatagramEndpoint::start(Handler on_datagram) {
  on_datagram_ = std::move(on_datagram);
  receive_next();
}

void DatagramEndpoint::receive_next() {
  socket_.async_wait(udp::socket::wait_read, [this](std::error_code error) {
    if (error == asio::error::operation_aborted || !socket_.is_open()) return;  // closed
    for (int read = 0; read < kReadsPerWakeUp && socket_.is_open(); ++read)
      if (!read_one()) break;
    if (socket_.is_open()) receive_next();
  });
}

// recvmsg rather than asio's receive_from: asio passes no ancillary data, and the kernel's
// count of the datagrams it dropped (SO_RXQ_OVFL) comes as ancillary data.
bool DatagramEndpoint::read_one() {
  iovec payload{buffer_.data(), buffer_.size()};
  alignas(cmsghdr) std::array<char, CMSG_SPACE(sizeof(std::uint32_t))> control{};
  msghdr message{};
  message.msg_name = from_.data();
  message.msg_namelen = static_cast<socklen_t>(from_.capacity());
  message.msg_iov = &payload;
  message.msg_iovlen = 1;
  message.msg_control = control.data();
  message.msg_controllen = control.size();
  const ssize_t n = ::recvmsg(socket_.native_handle(), &message, MSG_DONTWAIT);
  // EAGAIN: drained. Other errors (an ICMP "port unreachable" for an earlier send, say)
  // concern no one datagram: the next wake-up reads on.
  if (n < 0) return errno != EAGAIN && errno != EWOULDBLOCK;
  from_.resize(message.msg_namelen);
  for (cmsghdr* header = CMSG_FIRSTHDR(&message); header; header = CMSG_NXTHDR(&message, header))
    if (header->cmsg_level == SOL_SOCKET && header->cmsg_type == SO_RXQ_OVFL) {
      std::uint32_t dropped = 0;
      std::memcpy(&dropped, CMSG_DATA(header), sizeof dropped);
      kernel_dropped_.store(dropped, std::memory_order_relaxed);
    }
  take(static_cast<std::size_t>(n));
  return true;
}

void DatagramEndpoint::take(std::size_t bytes) {
  const std::int64_t arrival = monotonic_now_ns();
  const bool admitted = trusted(from_);
  if (!admitted && limiter_.limited(from_.address(), arrival)) {
    inspector_->count_unread(wire::Rejection::rate_limited);
    return;
  }
  if (std::optional<wire::Datagram> datagram =
          inspector_->inspect(std::span(buffer_.data(), bytes))) {
    if (!admitted) limiter_.prove(from_.address(), arrival);
    on_datagram_(std::move(*datagram), from_, arrival);
  } else if (!admitted) {
    limiter_.charge(from_.address(), arrival);
  }
}

bool DatagramEndpoint::trusted(const udp::endpoint& peer) const {
  return std::find(trusted_.begin(), trusted_.end(), peer) != trusted_.end();
}

void DatagramEndpoint::trust(const udp::endpoint& peer) {
  if (!trusted(peer)) trusted_.push_back(peer);
  limiter_.prove(peer.address(), monotonic_now_ns());  // an admitted peer's host is a known one
}

void DatagramEndpoint::distrust(const udp::endpoint& peer) { std::erase(trusted_, peer); }

void DatagramEndpoint::send(std::vector<std::uint8_t> datagram, const udp::endpoint& to) {
  auto bytes = std::make_shared<std::vector<std::uint8_t>>(std::move(datagram));
  socket_.async_send_to(asio::buffer(*bytes), to,
                        [bytes, sent = sent_](std::error_code error, std::size_t) {
                          if (!error) sent->fetch_add(1, std::memory_order_relaxed);
                        });
}

void DatagramEndpoint::close() {
  std::error_code ignored;
  socket_.close(ignored);
}

}  // namespace cohaptic::net
