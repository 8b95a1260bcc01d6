#include "common/util/monotonic_clock.h"
#include "support/raw_participant.h"

#include <sys/socket.h>
#include <sys/time.h>

#include <array>

#include "common/util/error.h"
#include "proto/wire/header.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic::testing {

using asio::ip::tcp;
using asio::ip::udp;

RawParticipant::RawParticipant(Options options, wire::ClientKeys keys)
    : options_(options),
      keys_(std::move(keys)),
      tcp_(io_),
      udp_(io_, udp::endpoint(asio::ip::make_address("127.0.0.1"), 0)),
      server_udp_(asio::ip::make_address("127.0.0.1"), options.server_port),
      key_(keys_.join_key()),
      frames_(key_, 0, keys_.join_sender(), options.encrypt),
      datagrams_(0, 0, options.encrypt) {}

RawParticipant::~RawParticipant() { stop(); }

void RawParticipant::stop() {
  stop_ = true;
  if (sender_.joinable()) sender_.join();
}

bool RawParticipant::read_some(std::chrono::steady_clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::microseconds>(
      deadline - std::chrono::steady_clock::now());
  if (left.count() <= 0) return false;
  const timeval timeout{static_cast<time_t>(left.count() / 1'000'000),
                        static_cast<suseconds_t>(left.count() % 1'000'000)};
  ::setsockopt(tcp_.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  std::array<std::uint8_t, 65536> buffer{};
  std::error_code error;
  const std::size_t n = tcp_.read_some(asio::buffer(buffer), error);
  if (error) return false;
  received_.insert(received_.end(), buffer.begin(), buffer.begin() + static_cast<long>(n));
  return true;
}

wire::Welcome RawParticipant::join(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  tcp_.open(tcp::v4());
  if (options_.tcp_receive_buffer > 0)
    tcp_.set_option(asio::socket_base::receive_buffer_size(options_.tcp_receive_buffer));
  tcp_.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), options_.server_port));
  wire::FrameReader reader(
      [this](std::uint32_t sender) { return sender == wire::kServerSender ? &key_ : nullptr; },
      {.expect_greeting = true, .allow_cleartext = !options_.encrypt});
  std::size_t fed = 0;
  const wire::Challenge mine = wire::random_challenge();
  while (true) {
    reader.feed(std::span(received_).subspan(fed));
    fed = received_.size();
    while (std::optional<wire::Control> control = reader.next()) {
      if (control->has_hello()) {
        wire::Control join;
        join.mutable_join()->set_user_name(options_.name);
        join.mutable_join()->set_udp_port(udp_.local_endpoint().port());
        join.mutable_join()->set_requested_slot(static_cast<std::uint32_t>(options_.slot + 1));
        join.mutable_join()->set_challenge(control->hello().challenge());
        join.mutable_join()->set_client_challenge(mine.data(), mine.size());
        join.mutable_join()->set_datagram_salt(datagrams_.salt());
        join_bytes_ = frames_.seal(join);
        send_raw(join_bytes_);
      } else if (control->has_error()) {
        throw Error("the server refused: " + control->error().text() + " (" +
                    control->error().code() + ")");
      } else if (control->has_welcome()) {
        const wire::Welcome& welcome = control->welcome();
        if (!wire::is_challenge(welcome.client_challenge(), mine))
          throw Error("a welcome that does not answer our join");
        key_ = *keys_.slot_key(welcome.slot());
        frames_.set_key(key_);
        datagrams_.set_key(key_);
        datagrams_.stamp().set_session(control->header().session());
        datagrams_.stamp().set_sender(wire::sender_of_slot(welcome.slot()));
        server_udp_.port(static_cast<std::uint16_t>(welcome.server_udp_port()));
        return welcome;
      }
    }
    if (!read_some(deadline)) throw Error("no welcome from the server in time");
  }
}

void RawParticipant::send_raw(const std::vector<std::uint8_t>& bytes) {
  asio::write(tcp_, asio::buffer(bytes));
}

void RawParticipant::send_sample(const Eigen::Vector3d& position) {
  wire::Datagram datagram;
  wire::ToolSample* sample = datagram.mutable_tool();
  sample->set_user(static_cast<std::uint32_t>(options_.slot));
  sample->set_sample_time_ns(monotonic_now_ns());  // one host: the server's clock is ours
  *sample->mutable_position() = wire::to_wire(position);
  sample->set_valid(true);
  std::error_code ignored;
  udp_.send_to(asio::buffer(datagrams_.seal(datagram)), server_udp_, 0, ignored);
  ++samples_sent_;
}

std::size_t RawParticipant::datagrams_within(std::chrono::milliseconds span) {
  const auto until = std::chrono::steady_clock::now() + span;
  std::array<std::uint8_t, 2048> buffer;
  std::size_t count = 0;
  udp_.non_blocking(true);
  while (std::chrono::steady_clock::now() < until) {
    std::error_code error;
    udp::endpoint from;
    udp_.receive_from(asio::buffer(buffer), from, 0, error);
    if (!error)
      ++count;
    else
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  udp_.non_blocking(false);
  return count;
}

void RawParticipant::press_along(std::function<Eigen::Vector3d(double)> path) {
  stop();
  stop_ = false;
  sender_ = std::thread([this, path = std::move(path)] {
    const auto start = std::chrono::steady_clock::now();
    auto next = start;
    while (!stop_) {
      send_sample(
          path(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()));
      next += std::chrono::milliseconds(1);
      std::this_thread::sleep_until(next);
    }
  });
}

}  // namespace cohaptic::testing
