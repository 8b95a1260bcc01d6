#include "support/unjoined_connections.h"

#include <array>
#include <thread>
#include <vector>

namespace cohaptic::testing {

using asio::ip::tcp;

asio::ip::address other_loopback(std::uint32_t k) { return asio::ip::address_v4(0x7f000002u + k); }

tcp::socket connect_from(asio::io_context& io, const asio::ip::address& source,
                         const tcp::endpoint& to) {
  tcp::socket socket(io);
  std::error_code error;
  socket.open(tcp::v4(), error);
  socket.bind({source, 0}, error);
  socket.connect(to, error);
  if (error) socket.close(error);
  return socket;
}

bool closed_by_peer(tcp::socket& socket) {
  if (!socket.is_open()) return true;
  socket.non_blocking(true);
  std::array<std::uint8_t, 4096> sink{};
  std::error_code error;
  while (!error) socket.read_some(asio::buffer(sink), error);
  return error != asio::error::would_block;
}

std::uint64_t hold_connections(const tcp::endpoint& to, int sources, int per_source,
                               std::chrono::steady_clock::time_point until) {
  asio::io_context io;
  std::vector<tcp::socket> held;
  const auto source_of = [&](std::size_t k) {
    return other_loopback(static_cast<std::uint32_t>(k) / static_cast<std::uint32_t>(per_source));
  };
  for (std::size_t k = 0; k < static_cast<std::size_t>(sources * per_source); ++k)
    held.push_back(connect_from(io, source_of(k), to));
  std::uint64_t opened = held.size();
  while (std::chrono::steady_clock::now() < until) {
    for (std::size_t k = 0; k < held.size(); ++k)
      if (closed_by_peer(held[k])) {
        held[k] = connect_from(io, source_of(k), to);
        ++opened;
      }
    std::this_thread::sleep_for(
        std::chrono::milliseconds(20));  // bounded, yet far faster than a join timer
  }
  return opened;
}

}  // namespace cohaptic::testing
