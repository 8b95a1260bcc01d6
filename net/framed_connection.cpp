#include "net/framed_connection.h"

#include <fmt/format.h>
#include <sys/ioctl.h>

#include <optional>
#include <span>

namespace cohaptic::net {

using asio::ip::tcp;

namespace {

// Bytes the kernel holds for `socket` that the peer's TCP has not acknowledged (Linux's
// TIOCOUTQ on a TCP socket: unsent plus unacknowledged); nullopt where it cannot tell.
std::optional<std::uint64_t> kernel_unacknowledged_bytes(tcp::socket& socket) {
#ifdef TIOCOUTQ
  int bytes = 0;
  if (::ioctl(socket.native_handle(), TIOCOUTQ, &bytes) == 0 && bytes >= 0)
    return static_cast<std::uint64_t>(bytes);
#endif
  return std::nullopt;
}

}  // namespace

FramedConnection::FramedConnection(Passkey, tcp::socket socket, wire::FrameReader reader,
                                   Handlers handlers, std::chrono::milliseconds write_timeout)
    : socket_(std::move(socket)),
      reader_(std::move(reader)),
      handlers_(std::make_shared<const Handlers>(std::move(handlers))),
      write_timer_(socket_.get_executor()),
      write_timeout_(write_timeout),
      delivery_timer_(socket_.get_executor()) {
  std::error_code error;
  const tcp::endpoint remote = socket_.remote_endpoint(error);
  peer_ = error ? "?" : fmt::format("{}:{}", remote.address().to_string(), remote.port());
  if (!error) peer_address_ = remote.address();
}

std::shared_ptr<FramedConnection> FramedConnection::start(tcp::socket socket,
                                                          wire::FrameReader reader,
                                                          Handlers handlers,
                                                          std::chrono::milliseconds write_timeout) {
  auto connection = std::make_shared<FramedConnection>(
      Passkey{}, std::move(socket), std::move(reader), std::move(handlers), write_timeout);
  connection->read_next();
  return connection;
}

void FramedConnection::read_next() {
  socket_.async_read_some(asio::buffer(buffer_),
                          [self = shared_from_this()](std::error_code error, std::size_t n) {
                            if (self->closed_) return;
                            if (error) {
                              if (error == asio::error::eof)
                                self->fail(CloseCause::peer_closed, "closed by the peer");
                              else
                                self->fail(CloseCause::io_error, error.message());
                              return;
                            }
                            try {
                              self->reader_.feed(std::span(self->buffer_.data(), n));
                              const std::shared_ptr<const Handlers> handlers = self->handlers_;
                              while (auto control = self->reader_.next()) {
                                handlers->on_control(*control);
                                if (self->closed_)
                                  return;  // the owner closed it while handling the frame
                              }
                            } catch (const wire::FrameError& e) {
                              self->rejection_ = e.reason();
                              self->fail(CloseCause::rejected_frame, e.what());
                              return;
                            }
                            self->read_next();
                          });
}

FramedConnection::Sent FramedConnection::send(std::vector<std::uint8_t> frame, FrameKind kind) {
  if (closed_) return Sent::closed;
  const BoundedWriteQueue::Push pushed = queue_.push(std::move(frame), kind);
  if (pushed == BoundedWriteQueue::Push::refused) {
    fail(CloseCause::write_queue_full,
         fmt::format("the peer stopped reading: {} frames that must arrive are waiting",
                     queue_.waiting()));
    return Sent::closed;
  }
  write_next();
  return pushed == BoundedWriteQueue::Push::queued ? Sent::queued : Sent::queued_after_drop;
}

void FramedConnection::write_next() {
  if (queue_.writing()) return;  // one at a time; its completion comes back here
  const std::vector<std::uint8_t>* frame = queue_.begin_write();
  if (!frame) {
    write_timer_.cancel();  // nothing in flight: nothing can stall
    return;
  }
  const std::uint64_t write = ++writes_started_;
  write_timer_.expires_after(write_timeout_);  // cancels the wait of the write before
  write_timer_.async_wait([self = shared_from_this(), write](std::error_code error) {
    if (error || self->closed_ || self->writes_started_ != write || !self->queue_.writing()) return;
    self->fail(CloseCause::write_stalled,
               fmt::format("the peer stopped reading: a frame has waited {:.1f} s to be written, "
                           "{} more behind it",
                           std::chrono::duration<double>(self->write_timeout_).count(),
                           self->queue_.waiting()));
  });
  asio::async_write(socket_, asio::buffer(*frame),
                    [self = shared_from_this()](std::error_code error, std::size_t written) {
                      self->queue_.end_write();
                      if (self->closed_) return;
                      if (error) {
                        self->fail(CloseCause::io_error, error.message());
                        return;
                      }
                      self->bytes_written_ += written;
                      self->watch_delivery();
                      self->write_next();
                    });
}

void FramedConnection::watch_delivery() {
  if (watching_delivery_) return;
  watching_delivery_ = true;
  acknowledged_at_ =
      std::chrono::steady_clock::now();  // all was acknowledged when the watch last ended
  check_delivery();
}

void FramedConnection::check_delivery() {
  const std::optional<std::uint64_t> waiting = kernel_unacknowledged_bytes(socket_);
  if (!waiting || *waiting == 0) {
    watching_delivery_ = false;
    return;
  }
  const auto now = std::chrono::steady_clock::now();
  if (const std::uint64_t acknowledged = bytes_written_ - *waiting;
      acknowledged > bytes_acknowledged_) {
    bytes_acknowledged_ = acknowledged;
    acknowledged_at_ = now;
  } else if (now - acknowledged_at_ >= 2 * write_timeout_) {
    fail(CloseCause::write_stalled,
         fmt::format(
             "the peer stopped reading: {} bytes sent have waited {:.1f} s for it to take any",
             *waiting, std::chrono::duration<double>(now - acknowledged_at_).count()));
    return;
  }
  delivery_timer_.expires_after(write_timeout_ / 5);
  delivery_timer_.async_wait([self = shared_from_this()](std::error_code error) {
    if (error || self->closed_) return;
    self->check_delivery();
  });
}

void FramedConnection::close() {
  if (closed_) return;
  closed_ = true;
  std::error_code ignored;
  socket_.close(ignored);
  write_timer_.cancel();
  delivery_timer_.cancel();
  handlers_.reset();
}

void FramedConnection::fail(CloseCause cause, std::string why) {
  if (closed_) return;
  std::shared_ptr<const Handlers> handlers = handlers_;
  close();
  asio::post(socket_.get_executor(), [self = shared_from_this(), handlers = std::move(handlers),
                                      cause, why = std::move(why)] {
    if (handlers->on_close) handlers->on_close(cause, why);
  });
}

}  // namespace cohaptic::net
