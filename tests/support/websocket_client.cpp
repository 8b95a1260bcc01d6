// C++17, asio's deprecated names allowed: websocketpp 0.8 (see view/CMakeLists.txt).
#include "support/websocket_client.h"

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

namespace cohaptic::testing {
namespace {

using Client = websocketpp::client<websocketpp::config::asio_client>;

}  // namespace

struct WebSocketClient::Impl {
  asio::io_context io;
  Client client;
  websocketpp::connection_hdl handle;
  std::thread thread;
  mutable std::mutex mutex;
  std::condition_variable changed;
  std::vector<std::string> messages;
  std::string last;
  std::size_t count = 0;
  std::uint64_t bytes = 0;
  bool keep = true, open = false, ended = false;
  int refused = 0, close_code = 0;

  template <class Predicate>
  bool wait(std::chrono::milliseconds timeout, Predicate predicate) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, timeout, predicate);
  }
};

WebSocketClient::WebSocketClient(const std::string& url, const std::string& origin)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.client.clear_access_channels(websocketpp::log::alevel::all);
  s.client.clear_error_channels(websocketpp::log::elevel::all);
  s.client.init_asio(&s.io);
  s.client.set_open_handler([&s](websocketpp::connection_hdl) {
    std::lock_guard lock(s.mutex);
    s.open = true;
    s.changed.notify_all();
  });
  const auto end = [&s](websocketpp::connection_hdl hdl) {
    const Client::connection_ptr connection = s.client.get_con_from_hdl(hdl);
    std::lock_guard lock(s.mutex);
    s.ended = true;
    s.close_code = connection->get_remote_close_code();
    if (!s.open) s.refused = connection->get_response_code();
    s.changed.notify_all();
  };
  s.client.set_close_handler(end);
  s.client.set_fail_handler(end);
  s.client.set_message_handler([&s](websocketpp::connection_hdl, Client::message_ptr message) {
    std::lock_guard lock(s.mutex);
    ++s.count;
    s.bytes += message->get_payload().size();
    s.last = message->get_payload();
    if (s.keep) s.messages.push_back(s.last);
    s.changed.notify_all();
  });
  websocketpp::lib::error_code error;
  const Client::connection_ptr connection = s.client.get_connection(url, error);
  if (error) throw std::runtime_error("websocket client: " + error.message());
  if (!origin.empty()) connection->append_header("Origin", origin);
  s.handle = connection->get_handle();
  s.client.connect(connection);
  s.thread = std::thread([&s] { s.io.run(); });
}

WebSocketClient::~WebSocketClient() {
  Impl& s = *impl_;
  asio::post(s.io, [&s] {
    websocketpp::lib::error_code error;
    s.client.close(s.handle, websocketpp::close::status::normal, "", error);
  });
  s.wait(std::chrono::milliseconds(500), [&s] { return s.ended; });
  s.io.stop();
  s.thread.join();
}

bool WebSocketClient::wait_open(std::chrono::milliseconds timeout) {
  impl_->wait(timeout, [this] { return impl_->open || impl_->ended; });
  std::lock_guard lock(impl_->mutex);
  return impl_->open && !impl_->ended;
}

bool WebSocketClient::wait_closed(std::chrono::milliseconds timeout) {
  return impl_->wait(timeout, [this] { return impl_->ended; });
}

bool WebSocketClient::wait_messages(std::size_t count, std::chrono::milliseconds timeout) {
  return impl_->wait(timeout, [this, count] { return impl_->count >= count; });
}

void WebSocketClient::send_binary(const std::string& payload) {
  asio::post(impl_->io, [s = impl_.get(), payload] {
    websocketpp::lib::error_code error;
    s->client.send(s->handle, payload, websocketpp::frame::opcode::binary, error);
  });
}

void WebSocketClient::send_text(const std::string& payload) {
  asio::post(impl_->io, [s = impl_.get(), payload] {
    websocketpp::lib::error_code error;
    s->client.send(s->handle, payload, websocketpp::frame::opcode::text, error);
  });
}

std::vector<std::string> WebSocketClient::messages() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->messages;
}

std::size_t WebSocketClient::message_count() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->count;
}

std::string WebSocketClient::last_message() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->last;
}

std::uint64_t WebSocketClient::bytes_received() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->bytes;
}

int WebSocketClient::refused_status() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->refused;
}

int WebSocketClient::close_code() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->close_code;
}

void WebSocketClient::count_only() {
  std::lock_guard lock(impl_->mutex);
  impl_->keep = false;
  impl_->messages.clear();
}

struct StalledWebSocket::Impl {
  asio::io_context io;
  asio::ip::tcp::socket socket{io};
  std::string unread;  // received, not yet parsed into frames
};

StalledWebSocket::StalledWebSocket(const std::string& host, std::uint16_t port)
    : impl_(std::make_unique<Impl>()) {
  const asio::ip::tcp::endpoint server(asio::ip::make_address(host), port);
  // The smallest receive buffer, so that the server's sends back up soon; set before the
  // connection, whose window it bounds: shrunk after, the kernel drops what the window let in
  // beyond it, and the server's retransmissions back off for seconds once it reads again.
  impl_->socket.open(server.protocol());
  impl_->socket.set_option(asio::socket_base::receive_buffer_size(4096));
  impl_->socket.connect(server);
  const std::string request =
      "GET /ws HTTP/1.1\r\nHost: " + host + ":" + std::to_string(port) +
      "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
  asio::write(impl_->socket, asio::buffer(request));
  std::string response;
  asio::error_code error;
  const std::size_t head =
      asio::read_until(impl_->socket, asio::dynamic_buffer(response), "\r\n\r\n", error);
  upgraded_ = !error && response.rfind("HTTP/1.1 101", 0) == 0;
  if (upgraded_) impl_->unread = response.substr(head);  // frames read with the response
}

StalledWebSocket::~StalledWebSocket() = default;

namespace {

// The payload of the first whole frame at the front of `bytes` (a server's frames are not
// masked), removed from it; nullopt while the frame is incomplete.
std::optional<std::string> take_frame(std::string& bytes) {
  if (bytes.size() < 2) return std::nullopt;
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(bytes[k]); };
  std::size_t header = 2;
  std::uint64_t length = byte(1) & 0x7f;
  if (length >= 126) {
    header = length == 126 ? 4 : 10;
    if (bytes.size() < header) return std::nullopt;
    length = 0;
    for (std::size_t k = 2; k < header; ++k) length = length << 8 | byte(k);
  }
  if (bytes.size() - header < length) return std::nullopt;
  std::string payload = bytes.substr(header, length);
  bytes.erase(0, header + length);
  return payload;
}

}  // namespace

bool StalledWebSocket::read_until_message(const std::string& wanted,
                                          std::chrono::milliseconds timeout) {
  Impl& s = *impl_;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::vector<char> chunk(64 * 1024);
  for (;;) {
    while (const std::optional<std::string> payload = take_frame(s.unread))
      if (*payload == wanted) return true;
    const auto left = deadline - std::chrono::steady_clock::now();
    if (left <= std::chrono::steady_clock::duration::zero()) return false;
    asio::error_code error;
    std::size_t received = 0;
    bool done = false;
    s.socket.async_read_some(asio::buffer(chunk), [&](const asio::error_code& e, std::size_t n) {
      error = e;
      received = n;
      done = true;
    });
    s.io.restart();
    s.io.run_for(left);
    if (!done) {  // timed out: cancel the read and let its handler run before returning
      s.socket.cancel();
      s.io.restart();
      s.io.run();
      return false;
    }
    if (error) return false;
    s.unread.append(chunk.data(), received);
  }
}

std::string http_get(const std::string& host, std::uint16_t port, const std::string& path) {
  return http_exchange(
      host, port, "GET " + path + " HTTP/1.1\r\nHost: " + host + "\r\nConnection: close\r\n\r\n");
}

std::string http_exchange(const std::string& host, std::uint16_t port, const std::string& request,
                          bool head_only) {
  asio::io_context io;
  asio::ip::tcp::socket socket(io);
  socket.connect({asio::ip::make_address(host), port});
  asio::write(socket, asio::buffer(request));
  std::string response;
  asio::error_code error;
  if (head_only)
    asio::read_until(socket, asio::dynamic_buffer(response), "\r\n\r\n", error);
  else
    asio::read(socket, asio::dynamic_buffer(response), error);  // to the end: the server closes
  return response;
}

}  // namespace cohaptic::testing
