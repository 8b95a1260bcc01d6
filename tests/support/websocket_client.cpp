// C++17, asio's deprecated names allowed: websocketpp 0.8 (see view/CMakeLists.txt).
#include "support/websocket_client.h"

#include <atomic>
#include <condition_variable>
#include <mutex>
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
};

StalledWebSocket::StalledWebSocket(const std::string& host, std::uint16_t port)
    : impl_(std::make_unique<Impl>()) {
  impl_->socket.connect({asio::ip::make_address(host), port});
  // The smallest receive buffer, so that the server's sends back up soon.
  impl_->socket.set_option(asio::socket_base::receive_buffer_size(4096));
  const std::string request =
      "GET /ws HTTP/1.1\r\nHost: " + host + ":" + std::to_string(port) +
      "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
  asio::write(impl_->socket, asio::buffer(request));
  std::string response;
  asio::error_code error;
  asio::read_until(impl_->socket, asio::dynamic_buffer(response), "\r\n\r\n", error);
  upgraded_ = !error && response.rfind("HTTP/1.1 101", 0) == 0;
}

StalledWebSocket::~StalledWebSocket() = default;

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
