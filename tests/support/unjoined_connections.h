// Connections made by hand for the security tests and the attack replay: one from a chosen
// loopback address, whether the peer has closed one, and many held open that never join.
// Blocking asio sockets on the caller's thread. Loopback only.
#pragma once

#include <asio.hpp>
#include <chrono>
#include <cstdint>

namespace cohaptic::testing {

/// 127.0.0.2 + k: source addresses other than the clients' 127.0.0.1.
asio::ip::address other_loopback(std::uint32_t k);

/// A TCP connection from `source` to `to`, or a closed socket if it could not be made.
asio::ip::tcp::socket connect_from(asio::io_context& io, const asio::ip::address& source,
                                   const asio::ip::tcp::endpoint& to);

/// Whether the peer closed `socket` (or it never opened): what it sent is read and
/// dropped, without waiting.
bool closed_by_peer(asio::ip::tcp::socket& socket);

/// Holds `per_source` connections from each of `sources` addresses (other_loopback(0), ...)
/// open to `to`, none of them ever sending, reopening each as soon as it is closed (checked
/// 50 times a second), until `until`; returns how many were opened in all.
std::uint64_t hold_connections(const asio::ip::tcp::endpoint& to, int sources, int per_source,
                               std::chrono::steady_clock::time_point until);

}  // namespace cohaptic::testing
