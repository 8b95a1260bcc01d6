#include "server/control_socket.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>

#include "common/util/error.h"

namespace cohaptic {

namespace {
constexpr std::size_t kMaxLine = 4096;
}  // namespace

class ControlSocket::Connection : public std::enable_shared_from_this<Connection> {
 public:
  Connection(asio::local::stream_protocol::socket socket, std::shared_ptr<const Handler> handler)
      : socket_(std::move(socket)), handler_(std::move(handler)), input_(kMaxLine) {}

  void read() {
    asio::async_read_until(
        socket_, input_, '\n',
        [self = shared_from_this()](std::error_code error, std::size_t size) {
          if (error ==
              asio::error::not_found) {  // a line longer than kMaxLine: answered, then closed
            self->answer({{"error", fmt::format("a command line is at most {} bytes", kMaxLine)}},
                         false);
            return;
          }
          if (error) return;  // closed by the peer or by close()
          std::string line(
              asio::buffers_begin(self->input_.data()),
              asio::buffers_begin(self->input_.data()) + static_cast<std::ptrdiff_t>(size));
          self->input_.consume(size);
          self->answer(self->run(line), true);
        });
  }

  void close() {
    std::error_code ignored;
    socket_.close(ignored);
  }

 private:
  nlohmann::json run(const std::string& line) {
    const nlohmann::json command = nlohmann::json::parse(line, nullptr, false);
    if (command.is_discarded() || !command.is_object())
      return {{"error", "not a JSON object on one line, e.g. {\"serve\": \"B\"}"}};
    try {
      return (*handler_)(command);
    } catch (const Error& e) {
      return {{"error", e.what()}};
    }
  }

  void answer(const nlohmann::json& reply, bool then_read) {
    auto text = std::make_shared<std::string>(reply.dump() + "\n");
    asio::async_write(
        socket_, asio::buffer(*text),
        [self = shared_from_this(), text, then_read](std::error_code error, std::size_t) {
          if (!error && then_read) self->read();
        });
  }

  asio::local::stream_protocol::socket socket_;
  std::shared_ptr<const Handler>
      handler_;  // outlives the ControlSocket, should a reply still be queued
  asio::streambuf input_;
};

ControlSocket::ControlSocket(asio::io_context& io, std::filesystem::path path, Handler handler)
    : path_(std::move(path)),
      handler_(std::make_shared<const Handler>(std::move(handler))),
      acceptor_(io) {
  std::error_code error;
  const auto status = std::filesystem::symlink_status(path_, error);
  if (!error && std::filesystem::exists(status)) {
    if (status.type() != std::filesystem::file_type::socket)
      throw Error(fmt::format("--control {}: the path exists and is not a socket; give a new path",
                              path_.string()));
    std::filesystem::remove(path_);  // a stale socket of an earlier server
  }
  // Only the server's user may connect: the socket is created under a 0077 umask.
  const mode_t previous = ::umask(0077);
  acceptor_.open(asio::local::stream_protocol());
  acceptor_.bind(asio::local::stream_protocol::endpoint(path_.string()), error);
  ::umask(previous);
  if (error)
    throw Error(fmt::format("--control {}: cannot bind: {}", path_.string(), error.message()));
  acceptor_.listen();
  accept();
}

ControlSocket::~ControlSocket() { close(); }

void ControlSocket::accept() {
  acceptor_.async_accept(
      [this](std::error_code error, asio::local::stream_protocol::socket socket) {
        if (error) return;  // closed
        auto connection = std::make_shared<Connection>(std::move(socket), handler_);
        std::erase_if(connections_, [](const std::weak_ptr<Connection>& c) { return c.expired(); });
        connections_.push_back(connection);
        connection->read();
        accept();
      });
}

void ControlSocket::close() {
  if (!acceptor_.is_open()) return;
  std::error_code ignored;
  acceptor_.close(ignored);
  for (const std::weak_ptr<Connection>& weak : connections_)
    if (const auto connection = weak.lock()) connection->close();
  connections_.clear();
  std::filesystem::remove(path_, ignored);
}

}  // namespace cohaptic
