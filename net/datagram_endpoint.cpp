#include "net/datagram_endpoint.h"

#include <span>

#include "proto/wire/header.h"

namespace cohaptic::net {

using asio::ip::udp;

DatagramEndpoint::DatagramEndpoint(asio::io_context& io, const udp::endpoint& local,
                                   std::unique_ptr<wire::DatagramInspector> inspector)
    : socket_(io), inspector_(std::move(inspector)) {
  socket_.open(local.protocol());
  socket_.bind(local);
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
    if (!error) {
      const std::int64_t arrival = wire::monotonic_now_ns();
      if (std::optional<wire::Datagram> datagram = inspector_->inspect(std::span(buffer_.data(), n)))
        on_datagram_(std::move(*datagram), from_, arrival);
    }
    receive_next();
  });
}

void DatagramEndpoint::send(std::vector<std::uint8_t> datagram, const udp::endpoint& to) {
  auto bytes = std::make_shared<std::vector<std::uint8_t>>(std::move(datagram));
  socket_.async_send_to(asio::buffer(*bytes), to, [bytes](std::error_code, std::size_t) {});
  ++sent_;
}

void DatagramEndpoint::close() {
  std::error_code ignored;
  socket_.close(ignored);
}

}  // namespace cohaptic::net
