// Compiled as C++17 (websocketpp 0.8 does not compile as C++20 with GCC 12), with asio's
// deprecated names allowed (websocketpp uses io_service). Its asio objects never leave
// this file: the io_context, the endpoint and the connections are all in Impl.
#include "view/view_server.h"

#include <spdlog/spdlog.h>

#include <atomic>
#include <map>
#include <mutex>
#include <optional>
#include <thread>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include "cohaptic/view.pb.h"
#include "common/util/error.h"
#include "common/util/printable.h"
#include "view/browser_input.h"
#include "view/view_assets.h"

namespace cohaptic::view {
namespace {

using WsServer = websocketpp::server<websocketpp::config::asio>;
using websocketpp::connection_hdl;

/// Time the closing handshakes get at stop().
constexpr auto kCloseGrace = std::chrono::milliseconds(200);
/// After an accept() that failed (out of file descriptors, say), the wait before the next.
constexpr auto kAcceptRetry = std::chrono::milliseconds(100);
/// While a browser is too busy for the newest messages, the wait before offering them again:
/// nothing else would, were nothing more published.
constexpr auto kCatchUpRetry = std::chrono::milliseconds(5);
/// The kernel's send buffer of a browser's socket: a browser that stops reading holds at
/// most this in the kernel (and max_buffered_bytes, shared with the others, in the server).
constexpr int kBrowserSendBufferBytes = 256 << 10;

// A binary WebSocket frame of `payload`, framed once (a server's frames are not masked) and
// marked prepared, so that every browser's connection sends this one buffer, not a copy.
WsServer::message_ptr prepared_frame(const WsServer::connection_ptr& connection,
                                     const std::string& payload) {
  WsServer::message_ptr frame =
      connection->get_message(websocketpp::frame::opcode::binary, payload.size());
  const websocketpp::frame::basic_header basic(websocketpp::frame::opcode::binary, payload.size(),
                                               true, false);
  frame->set_header(websocketpp::frame::prepare_header(
      basic, websocketpp::frame::extended_header(payload.size())));
  frame->set_payload(payload);
  frame->set_prepared(true);
  return frame;
}

}  // namespace

struct ViewServer::Impl {
  struct Browser {
    std::array<std::uint64_t, kChannels> sent{};       // newest sequence sent, per channel
    std::array<std::uint64_t, kChannels> accounted{};  // sent or counted as dropped up to here
  };

  ViewServerOptions options;
  CommandHandler on_command;
  AssetTable assets;
  asio::io_context io;
  WsServer server;
  asio::steady_timer accept_retry{io};
  asio::steady_timer catch_up{io};
  std::int64_t last_accept_warning_ns = 0;
  std::uint16_t port = 0;
  std::thread thread;
  bool stopped = false;

  // The newest message of each channel; publish() and flush() swap pointers under the mutex.
  std::mutex mutex;
  std::array<std::shared_ptr<const std::string>, kChannels> newest;
  std::array<std::uint64_t, kChannels> sequence{};
  std::atomic<bool> flush_pending{false};
  std::atomic<int> connected{0};  // browsers, for watched()

  // The server's thread only.
  bool stopped_serving = false;  // stop() has begun closing the browsers
  bool catch_up_armed = false;
  std::map<connection_hdl, Browser, std::owner_less<connection_hdl>> browsers;

  mutable std::mutex counters_mutex;
  ViewCounters counters;

  Impl(ViewServerOptions o, CommandHandler handler)
      : options(std::move(o)),
        on_command(std::move(handler)),
        assets(load_assets(options.assets, options.proto, options.page)) {
    server.clear_access_channels(websocketpp::log::alevel::all);
    server.clear_error_channels(websocketpp::log::elevel::all);
    server.init_asio(&io);
    server.set_reuse_addr(true);
    server.set_max_message_size(options.max_command_bytes);
    server.set_max_http_body_size(0);  // a GET has none: nobody makes the server buffer one
    server.set_socket_init_handler([](connection_hdl, asio::ip::tcp::socket& socket) {
      asio::error_code ignored;
      socket.set_option(asio::socket_base::send_buffer_size(kBrowserSendBufferBytes), ignored);
    });
    server.set_http_handler([this](connection_hdl hdl) { http(hdl); });
    server.set_validate_handler([this](connection_hdl hdl) { return validate(hdl); });
    server.set_open_handler([this](connection_hdl hdl) { opened(hdl); });
    server.set_close_handler([this](connection_hdl hdl) { closed(hdl); });
    server.set_fail_handler([this](connection_hdl hdl) { closed(hdl); });
    server.set_message_handler(
        [this](connection_hdl hdl, WsServer::message_ptr message) { received(hdl, message); });
    websocketpp::lib::error_code error;
    asio::error_code address_error;
    const auto address = asio::ip::make_address(options.host, address_error);
    if (address_error) throw Error("view: '" + options.host + "' is not an IP address");
    server.listen(asio::ip::tcp::endpoint(address, options.port), error);
    if (error)
      throw Error("view: cannot listen on " + options.host + ":" + std::to_string(options.port) +
                  ": " + error.message());
    port = server.get_local_endpoint(error).port();
    accept();
  }

  // websocketpp's own accept loop (start_accept) accepts again at once after a failure, so
  // out of file descriptors it spins; this one waits kAcceptRetry first.
  void accept() {
    const WsServer::connection_ptr connection = server.get_connection();
    websocketpp::lib::error_code error;
    if (connection)
      server.async_accept(
          connection,
          [this, connection](const websocketpp::lib::error_code& accept_error) {
            if (!accept_error) {
              connection->start();
              accept();
            } else {
              connection->terminate(accept_error);
              accept_failed(accept_error);
            }
          },
          error);
    if (!connection || error) {
      if (connection) connection->terminate(error);
      accept_failed(error);
    }
  }

  void accept_failed(const websocketpp::lib::error_code& error) {
    if (!server.is_listening()) return;  // stopping
    count([](ViewCounters& c) { ++c.accept_errors; });
    const std::int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                 std::chrono::steady_clock::now().time_since_epoch())
                                 .count();
    if (now - last_accept_warning_ns >
        1'000'000'000) {  // once a second at most: the counter has the rest
      spdlog::warn("view: accept failed: {}; accepting again in {} ms", error.message(),
                   kAcceptRetry.count());
      last_accept_warning_ns = now;
    }
    accept_retry.expires_after(kAcceptRetry);
    accept_retry.async_wait([this](const asio::error_code& timer_error) {
      if (!timer_error) accept();
    });
  }

  template <class Change>
  void count(Change change) {
    std::lock_guard lock(counters_mutex);
    change(counters);
  }

  void http(connection_hdl hdl) {
    const WsServer::connection_ptr connection = server.get_con_from_hdl(hdl);
    count([](ViewCounters& c) { ++c.http_requests; });
    const Asset* asset = connection->get_request().get_method() == "GET"
                             ? find_asset(assets, connection->get_resource())
                             : nullptr;
    if (!asset) {
      connection->set_status(websocketpp::http::status_code::not_found);
      connection->set_body("not found\n");
      return;
    }
    connection->set_status(websocketpp::http::status_code::ok);
    connection->replace_header("Content-Type", asset->content_type);
    connection->replace_header("Cache-Control", "no-cache");
    connection->set_body(asset->body);
  }

  // The handshake: the right path, the token when one is required, and no foreign page.
  bool validate(connection_hdl hdl) {
    const WsServer::connection_ptr connection = server.get_con_from_hdl(hdl);
    const std::string resource = connection->get_resource();
    const std::string origin = connection->get_request_header("Origin");
    const std::string host = connection->get_request_header("Host");
    std::string refusal = handshake_refusal(resource, origin, host, options.token);
    const bool full = refusal.empty() && static_cast<int>(browsers.size()) >= options.max_browsers;
    if (full) refusal = "already " + std::to_string(browsers.size()) + " browsers connected";
    if (refusal.empty()) return true;
    count([](ViewCounters& c) { ++c.refused; });
    spdlog::warn("view: refused a browser from {}: {}", connection->get_remote_endpoint(),
                 printable(refusal, 200));
    connection->set_status(full ? websocketpp::http::status_code::service_unavailable
                                : websocketpp::http::status_code::forbidden);
    return false;
  }

  void opened(connection_hdl hdl) {
    Browser& browser = browsers[hdl];
    {
      std::lock_guard lock(mutex);  // what was published before it came is not its loss
      for (std::size_t channel = 0; channel < kChannels; ++channel)
        browser.accounted[channel] = sequence[channel] > 0 ? sequence[channel] - 1 : 0;
    }
    connected = static_cast<int>(browsers.size());
    count([this](ViewCounters& c) {
      ++c.connections;
      c.browsers = static_cast<int>(browsers.size());
    });
    spdlog::info("view: a browser connected from {} ({} now)",
                 server.get_con_from_hdl(hdl)->get_remote_endpoint(), browsers.size());
    flush();
  }

  void closed(connection_hdl hdl) {
    if (browsers.erase(hdl) == 0) return;
    connected = static_cast<int>(browsers.size());
    count([this](ViewCounters& c) { c.browsers = static_cast<int>(browsers.size()); });
  }

  void received(connection_hdl hdl, const WsServer::message_ptr& message) {
    const std::optional<Command> command =
        message->get_opcode() == websocketpp::frame::opcode::binary
            ? parse_command(message->get_payload())
            : std::nullopt;
    if (!command) {
      count([](ViewCounters& c) { ++c.closed_for_bad_message; });
      websocketpp::lib::error_code error;
      server.close(hdl, websocketpp::close::status::invalid_payload, "not a view Command", error);
      return;
    }
    if (on_command) on_command(*command);
  }

  // Each browser gets the newest message of each channel it has not had, scene first;
  // one still busy with earlier messages gets nothing new until it has caught up, when the
  // catch-up timer offers it whatever is newest then.
  void flush() {
    flush_pending = false;
    std::array<std::shared_ptr<const std::string>, kChannels> messages;
    std::array<std::uint64_t, kChannels> sequences{};
    {
      std::lock_guard lock(mutex);
      messages = newest;
      sequences = sequence;
    }
    if (!messages[static_cast<std::size_t>(Channel::scene)]) return;
    std::uint64_t sent = 0, bytes = 0, dropped = 0;
    bool someone_busy = false;
    std::array<WsServer::message_ptr, kChannels>
        frames;  // framed on first use, shared by every browser
    for (auto& [hdl, browser] : browsers) {
      websocketpp::lib::error_code error;
      const WsServer::connection_ptr connection = server.get_con_from_hdl(hdl, error);
      if (error) continue;
      for (std::size_t channel = 0; channel < kChannels; ++channel) {
        if (!messages[channel] || browser.sent[channel] == sequences[channel]) continue;
        // Everything older than the newest that it has not had, it never will.
        if (sequences[channel] - 1 > browser.accounted[channel]) {
          dropped += sequences[channel] - 1 - browser.accounted[channel];
          browser.accounted[channel] = sequences[channel] - 1;
        }
        if (channel != static_cast<std::size_t>(Channel::scene) &&
            connection->get_buffered_amount() > options.max_buffered_bytes) {
          someone_busy = true;
          continue;
        }
        if (!frames[channel]) frames[channel] = prepared_frame(connection, *messages[channel]);
        error = connection->send(frames[channel]);
        if (error) break;
        browser.sent[channel] = browser.accounted[channel] = sequences[channel];
        ++sent;
        bytes += messages[channel]->size();
      }
    }
    count([&](ViewCounters& c) {
      c.messages_sent += sent;
      c.bytes_sent += bytes;
      c.dropped += dropped;
    });
    if (someone_busy && !catch_up_armed && !stopped_serving) {
      catch_up_armed = true;
      catch_up.expires_after(kCatchUpRetry);
      catch_up.async_wait([this](const asio::error_code& error) {
        catch_up_armed = false;
        if (!error) flush();
      });
    }
  }
};

ViewServer::ViewServer(ViewServerOptions options, CommandHandler on_command)
    : impl_(std::make_unique<Impl>(std::move(options), std::move(on_command))) {}

ViewServer::~ViewServer() { stop(); }

void ViewServer::start() {
  impl_->thread = std::thread([impl = impl_.get()] { impl->io.run(); });
}

void ViewServer::stop() {
  Impl& s = *impl_;
  if (s.stopped) return;
  s.stopped = true;
  asio::post(s.io, [&s] {
    websocketpp::lib::error_code error;
    s.server.stop_listening(error);
    s.accept_retry.cancel();
    s.stopped_serving = true;
    s.catch_up.cancel();
    for (const auto& [hdl, browser] : s.browsers)
      s.server.close(hdl, websocketpp::close::status::going_away, "server stopped", error);
    auto timer = std::make_shared<asio::steady_timer>(s.io, kCloseGrace);
    timer->async_wait([&s, timer](const asio::error_code&) { s.io.stop(); });
  });
  if (s.thread.joinable()) s.thread.join();
}

std::uint16_t ViewServer::port() const { return impl_->port; }

std::string ViewServer::url(bool with_token) const {
  const Impl& s = *impl_;
  const bool v6 = s.options.host.find(':') != std::string::npos;
  std::string url = "http://" + (v6 ? "[" + s.options.host + "]" : s.options.host) + ":" +
                    std::to_string(s.port) + "/";
  if (with_token && !s.options.token.empty()) url += "?token=" + s.options.token;
  return url;
}

void ViewServer::publish(Channel channel, std::string message) {
  Impl& s = *impl_;
  auto shared = std::make_shared<const std::string>(std::move(message));
  {
    std::lock_guard lock(s.mutex);
    s.newest[static_cast<std::size_t>(channel)] = std::move(shared);
    ++s.sequence[static_cast<std::size_t>(channel)];
  }
  if (!s.flush_pending.exchange(true)) asio::post(s.io, [&s] { s.flush(); });
}

bool ViewServer::watched() const { return impl_->connected.load() > 0; }

void ViewServer::post(std::function<void()> task) { asio::post(impl_->io, std::move(task)); }

ViewCounters ViewServer::counters() const {
  std::lock_guard lock(impl_->counters_mutex);
  return impl_->counters;
}

}  // namespace cohaptic::view
