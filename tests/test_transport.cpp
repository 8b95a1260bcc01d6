// The transport layer (net/) on real loopback sockets:
//   - the bounded write queue keeps its policy under any sequence of pushes and writes:
//     never more than its limit waiting, never a must-arrive frame lost, the newest
//     newest-wins frame always kept, frames written in the order pushed;
//   - a framed connection carries sealed frames in order both ways, and closes on a frame
//     whose tag does not verify;
//   - against a peer that stops reading, it stays bounded: it drops superseded newest-wins
//     frames, and when it has read again every must-arrive frame and the newest
//     newest-wins frame arrived; with nothing it may drop, it closes the connection;
//   - a frame the kernel does not take within the write timeout closes the connection,
//     even when only newest-wins frames wait;
//   - the UDP endpoint hands over the datagrams that pass the inspector and counts every
//     other by its reason;
//   - the per-source rate limit against a token-bucket model on a driven clock, and on a
//     real socket: a flooding source is heard only at the refill rate, while an admitted
//     peer on the same address loses nothing;
//   - delivery over an ordered link with jitter (the server's injected delay on TCP) keeps
//     the order of a burst: timers due at one instant, or run late, never swap two frames.
#include <gtest/gtest.h>

#include <array>
#include <asio.hpp>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <string>

#include "common/util/monotonic_clock.h"
#include "net/bounded_write_queue.h"
#include "net/datagram_endpoint.h"
#include "net/delayed_delivery.h"
#include "net/framed_connection.h"
#include "net/source_rate_limiter.h"
#include "proto/wire/frame_codec.h"
#include "proto/wire/sealer.h"
#include "proto/wire/session_key.h"
#include "proto/wire/traffic_keys.h"

namespace cohaptic::net {
namespace {

using asio::ip::tcp;
using asio::ip::udp;
using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

constexpr std::uint64_t kTransportSession = 0x7e57'0001;

// ---- the write queue's policy ----

// Frame i is i as 4 bytes: the tests can tell frames apart after they went through the queue.
Bytes frame_of(std::uint32_t i) {
  return {static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(i >> 8),
          static_cast<std::uint8_t>(i >> 16), static_cast<std::uint8_t>(i >> 24)};
}
std::uint32_t index_of(const Bytes& frame) {
  return frame[0] | static_cast<std::uint32_t>(frame[1]) << 8 |
         static_cast<std::uint32_t>(frame[2]) << 16 | static_cast<std::uint32_t>(frame[3]) << 24;
}

TEST(BoundedWriteQueue, DropsTheOldestSupersededNewestWinsFrameAndRefusesWhenNothingCanGo) {
  BoundedWriteQueue queue(3);
  EXPECT_EQ(queue.push(frame_of(0), FrameKind::newest_wins), BoundedWriteQueue::Push::queued);
  EXPECT_EQ(index_of(*queue.begin_write()), 0u);  // in flight from now on
  EXPECT_EQ(queue.push(frame_of(1), FrameKind::must_arrive), BoundedWriteQueue::Push::queued);
  EXPECT_EQ(queue.push(frame_of(2), FrameKind::newest_wins), BoundedWriteQueue::Push::queued);
  EXPECT_EQ(queue.push(frame_of(3), FrameKind::must_arrive), BoundedWriteQueue::Push::queued);
  // Full. A must-arrive frame: the only newest-wins frame waiting is the newest, so it stays.
  EXPECT_EQ(queue.push(frame_of(4), FrameKind::must_arrive), BoundedWriteQueue::Push::refused);
  // A newest-wins frame supersedes frame 2 (not frame 0, which is being written).
  EXPECT_EQ(queue.push(frame_of(5), FrameKind::newest_wins),
            BoundedWriteQueue::Push::queued_after_drop);
  EXPECT_EQ(queue.dropped(), 1u);
  EXPECT_EQ(queue.waiting(), 3u);
  EXPECT_EQ(queue.begin_write(), nullptr);  // one at a time
  std::vector<std::uint32_t> written;
  queue.end_write();
  while (const Bytes* frame = queue.begin_write()) {
    written.push_back(index_of(*frame));
    queue.end_write();
  }
  EXPECT_EQ(written, (std::vector<std::uint32_t>{1, 3, 5}));
}

// Random pushes and writes against the policy's promises.
TEST(BoundedWriteQueue, UnderRandomTrafficKeepsEveryMustArriveFrameAndTheNewestNewestWinsFrame) {
  std::mt19937 random(11);
  for (int trial = 0; trial < 50; ++trial) {
    const std::size_t limit = 1 + random() % 6;
    BoundedWriteQueue queue(limit);
    std::set<std::uint32_t> must_arrive, refused;
    std::vector<std::uint32_t> written;
    std::uint32_t newest = 0;
    bool any_newest_wins = false, in_flight = false;
    for (std::uint32_t i = 0; i < 400; ++i) {
      const bool newest_wins = random() % 3 != 0;
      const auto pushed =
          queue.push(frame_of(i), newest_wins ? FrameKind::newest_wins : FrameKind::must_arrive);
      if (pushed == BoundedWriteQueue::Push::refused) {
        refused.insert(i);
      } else if (newest_wins) {
        newest = i;
        any_newest_wins = true;
      } else {
        must_arrive.insert(i);
      }
      ASSERT_LE(queue.waiting(), limit);
      // The socket writes now and then.
      if (random() % 4 == 0) {
        if (in_flight) {
          queue.end_write();
          in_flight = false;
        }
        if (const Bytes* frame = queue.begin_write()) {
          written.push_back(index_of(*frame));
          in_flight = true;
        }
      }
    }
    if (in_flight) queue.end_write();
    while (const Bytes* frame = queue.begin_write()) {
      written.push_back(index_of(*frame));
      queue.end_write();
    }
    EXPECT_TRUE(std::is_sorted(written.begin(), written.end())) << "frames left out of order";
    const std::set<std::uint32_t> arrived(written.begin(), written.end());
    for (std::uint32_t i : must_arrive)
      EXPECT_TRUE(arrived.count(i)) << "must-arrive frame " << i << " was lost";
    if (any_newest_wins) {
      EXPECT_TRUE(arrived.count(newest)) << "the newest newest-wins frame was lost";
    }
    EXPECT_EQ(arrived.size() + queue.dropped() + refused.size(), 400u);
  }
}

// ---- the framed connection ----

// A loopback TCP pair: `client` connected to `server`.
struct TcpPair {
  asio::io_context io;
  tcp::socket server{io}, client{io};
  explicit TcpPair(int receive_buffer_bytes = 0) {
    tcp::acceptor acceptor(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    client.open(tcp::v4());
    if (receive_buffer_bytes > 0)
      client.set_option(asio::socket_base::receive_buffer_size(receive_buffer_bytes));
    client.connect(acceptor.local_endpoint());
    acceptor.accept(server);
  }
  // Runs the I/O until `done` or the timeout.
  template <class Done>
  bool run_until(Done done, std::chrono::seconds timeout = 10s) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (!done() && std::chrono::steady_clock::now() < end) {
      io.restart();
      io.run_for(5ms);
    }
    return done();
  }
};

// Both ends of these tests seal with one participant's key and open any sender's frames with it.
wire::TrafficKey test_key() { return wire::participant_key(wire::development_key(), 0); }
wire::FrameReader reader_with(const wire::TrafficKey& key) {
  return wire::FrameReader([key](std::uint32_t) { return &key; });
}

wire::Control event(const std::string& kind, const std::string& text) {
  wire::Control control;
  control.mutable_event()->set_kind(kind);
  control.mutable_event()->set_text(text);
  return control;
}

TEST(FramedConnection, CarriesSealedFramesInOrderBothWaysAndClosesOnABadTag) {
  const wire::TrafficKey key = test_key();
  TcpPair pair;
  std::vector<std::string> at_server, at_client;
  std::map<std::string, CloseCause> closed;
  const auto handlers = [&](std::vector<std::string>& received, const std::string& side) {
    FramedConnection::Handlers h;
    h.on_control = [&received](const wire::Control& control) {
      received.push_back(control.event().text());
    };
    h.on_close = [&closed, side](CloseCause cause, const std::string&) { closed[side] = cause; };
    return h;
  };
  auto server = FramedConnection::start(std::move(pair.server), reader_with(key),
                                        handlers(at_server, "server"));
  auto client = FramedConnection::start(std::move(pair.client), reader_with(key),
                                        handlers(at_client, "client"));
  wire::FrameSealer server_sealer(key, kTransportSession, 0),
      client_sealer(key, kTransportSession, 1);
  for (int i = 0; i < 100; ++i) {
    wire::Control to_client = event("count", std::to_string(i)),
                  to_server = event("count", std::to_string(-i));
    server->send(server_sealer.seal(to_client), FrameKind::must_arrive);
    client->send(client_sealer.seal(to_server), FrameKind::must_arrive);
    pair.io.restart();
    pair.io.poll();  // the sockets write as the frames come, as on an I/O thread
  }
  ASSERT_TRUE(pair.run_until([&] { return at_client.size() == 100 && at_server.size() == 100; }));
  for (int i = 0; i < 100; ++i) {
    EXPECT_EQ(at_client[static_cast<std::size_t>(i)], std::to_string(i));
    EXPECT_EQ(at_server[static_cast<std::size_t>(i)], std::to_string(-i));
  }
  // A frame with one bit of its tag flipped: the client's reader rejects it and closes.
  wire::Control forged = event("forged", "x");
  Bytes bytes = server_sealer.seal(forged);
  bytes.back() ^= 1;
  server->send(std::move(bytes), FrameKind::must_arrive);
  ASSERT_TRUE(pair.run_until([&] { return closed.size() == 2; }));
  EXPECT_EQ(closed["client"], CloseCause::rejected_frame);
  EXPECT_EQ(closed["server"], CloseCause::peer_closed);
  EXPECT_EQ(at_client.size(), 100u);  // the forged frame never reached its handler
  EXPECT_TRUE(client->closed());
}

TEST(FramedConnection, AgainstAPeerThatStopsReadingItStaysBoundedAndTheFramesThatMustArriveDo) {
  const wire::TrafficKey key = test_key();
  TcpPair pair(64 * 1024);  // a small receive window: the peer's kernel takes few frames
  bool sender_closed = false;
  FramedConnection::Handlers handlers;
  handlers.on_control = [](const wire::Control&) {};
  handlers.on_close = [&](CloseCause, const std::string&) { sender_closed = true; };
  pair.server.set_option(asio::socket_base::send_buffer_size(64 * 1024));
  auto sender =
      FramedConnection::start(std::move(pair.server), reader_with(key), std::move(handlers));
  wire::FrameSealer sealer(key, kTransportSession, 0);
  // 200 frames of 100 kB, every 20th a must-arrive event, the rest newest-wins "IRs".
  const std::string payload(100'000, 'p');
  constexpr int kFrames = 200;
  std::size_t most_waiting = 0;
  for (int i = 0; i < kFrames; ++i) {
    const bool must_arrive = i % 20 == 0;
    wire::Control control = event(must_arrive ? "event" : "ir", std::to_string(i) + " " + payload);
    EXPECT_NE(sender->send(sealer.seal(control),
                           must_arrive ? FrameKind::must_arrive : FrameKind::newest_wins),
              FramedConnection::Sent::closed);
    pair.io.restart();
    pair.io.poll();  // the socket takes what it can
    most_waiting = std::max(most_waiting, sender->frames_waiting());
  }
  EXPECT_LE(most_waiting, kMaxWaitingFrames);
  EXPECT_GT(sender->frames_dropped(), 50u) << "the peer's kernel buffers took more than expected";
  EXPECT_FALSE(sender_closed);

  // The peer reads again: everything still queued arrives, in order.
  std::vector<std::pair<std::string, int>> received;
  FramedConnection::Handlers receiving;
  receiving.on_control = [&](const wire::Control& control) {
    received.emplace_back(control.event().kind(), std::stoi(control.event().text()));
  };
  receiving.on_close = [](CloseCause, const std::string&) {};
  auto reader =
      FramedConnection::start(std::move(pair.client), reader_with(key), std::move(receiving));
  ASSERT_TRUE(
      pair.run_until([&] { return !received.empty() && received.back().second == kFrames - 1; }));
  int irs = 0;
  std::vector<int> events;
  for (std::size_t i = 0; i < received.size(); ++i) {
    if (i > 0) {
      EXPECT_LT(received[i - 1].second, received[i].second);
    }
    if (received[i].first == "event")
      events.push_back(received[i].second);
    else
      ++irs;
  }
  EXPECT_EQ(events.size(), static_cast<std::size_t>(kFrames / 20))
      << "a must-arrive frame was lost";
  EXPECT_EQ(static_cast<std::uint64_t>(irs) + sender->frames_dropped(),
            static_cast<std::uint64_t>(kFrames - kFrames / 20));
  std::printf(
      "  %d frames to a peer that stopped reading: %lu newest-wins frames dropped, at most %zu "
      "waiting\n",
      kFrames, static_cast<unsigned long>(sender->frames_dropped()), most_waiting);
}

TEST(FramedConnection, ClosesWhenFramesThatMustArrivePileUpUnread) {
  const wire::TrafficKey key = test_key();
  TcpPair pair(64 * 1024);
  pair.server.set_option(asio::socket_base::send_buffer_size(64 * 1024));
  std::optional<CloseCause> cause;
  FramedConnection::Handlers handlers;
  handlers.on_control = [](const wire::Control&) {};
  handlers.on_close = [&](CloseCause c, const std::string&) { cause = c; };
  auto sender =
      FramedConnection::start(std::move(pair.server), reader_with(key), std::move(handlers));
  wire::FrameSealer sealer(key, kTransportSession, 0);
  const std::string payload(100'000, 'e');
  int sent = 0;
  for (; sent < 1000 && !sender->closed(); ++sent) {
    wire::Control control = event("event", payload);
    sender->send(sealer.seal(control), FrameKind::must_arrive);
    pair.io.restart();
    pair.io.poll();
  }
  ASSERT_TRUE(pair.run_until([&] { return cause.has_value(); }));
  EXPECT_EQ(*cause, CloseCause::write_queue_full);
  EXPECT_LT(sent, 1000);
  EXPECT_EQ(sender->send(Bytes(10), FrameKind::must_arrive), FramedConnection::Sent::closed);
}

// A connection started on `pair.server` with `write_timeout`, keeping why it closed.
struct WatchedSender {
  std::optional<CloseCause> cause;
  std::string why;
  std::shared_ptr<FramedConnection> connection;
  WatchedSender(TcpPair& pair, const wire::TrafficKey& key,
                std::chrono::milliseconds write_timeout) {
    FramedConnection::Handlers handlers;
    handlers.on_control = [](const wire::Control&) {};
    handlers.on_close = [this](CloseCause c, const std::string& w) {
      cause = c;
      why = w;
    };
    connection = FramedConnection::start(std::move(pair.server), reader_with(key),
                                         std::move(handlers), write_timeout);
  }
  WatchedSender(const WatchedSender&) = delete;  // the handler holds `this`
  WatchedSender& operator=(const WatchedSender&) = delete;
};

TEST(FramedConnection, ClosesWhenAWriteStallsPastTheTimeoutEvenWithOnlyNewestWinsFramesWaiting) {
  const wire::TrafficKey key = test_key();
  TcpPair pair(64 * 1024);
  pair.server.set_option(asio::socket_base::send_buffer_size(64 * 1024));
  constexpr auto kTimeout = 300ms;
  WatchedSender watched(pair, key, kTimeout);
  wire::FrameSealer sealer(key, kTransportSession, 0);
  const std::string payload(100'000, 'i');
  const auto started = std::chrono::steady_clock::now();
  // Newest-wins frames only, which the queue may always drop: without the timeout it would never
  // close.
  while (!watched.cause && std::chrono::steady_clock::now() - started < 10s) {
    wire::Control control = event("ir", payload);
    watched.connection->send(sealer.seal(control), FrameKind::newest_wins);
    pair.io.restart();
    pair.io.run_for(20ms);
  }
  ASSERT_TRUE(watched.cause) << "still open after 10 s";
  EXPECT_EQ(*watched.cause, CloseCause::write_stalled);
  EXPECT_NE(watched.why.find("the peer stopped reading"), std::string::npos) << watched.why;
  EXPECT_GE(std::chrono::steady_clock::now() - started, kTimeout)
      << "closed before any write could have stalled that long";
  EXPECT_LE(watched.connection->frames_waiting(), kMaxWaitingFrames);
}

// Small must-arrive frames, which the kernel's buffers take for minutes: the connection
// stays open while the peer reads, however slowly, and closes as stalled once its TCP has
// acknowledged nothing for twice the write timeout, though no write ever waited.
TEST(FramedConnection, ClosesWhenThePeerStopsTakingFramesThatTheKernelStillTakes) {
  const wire::TrafficKey key = test_key();
  TcpPair pair(4096);  // the peer's kernel takes a few frames, then acknowledges nothing unread
  constexpr auto kTimeout = 200ms;
  WatchedSender watched(pair, key, kTimeout);
  wire::FrameSealer sealer(key, kTransportSession, 0);
  // The peer reads in pieces of 512 bytes, one every 10 ms: its TCP acknowledges as it goes.
  bool reading = true;
  std::array<std::uint8_t, 512> sink{};
  std::function<void()> read_a_little = [&] {
    if (!reading) return;
    pair.client.async_read_some(asio::buffer(sink), [&](std::error_code error, std::size_t) {
      if (error) return;
      auto pause = std::make_shared<asio::steady_timer>(pair.io, 10ms);
      pause->async_wait([&, pause](std::error_code) { read_a_little(); });
    });
  };
  read_a_little();
  const auto send_for = [&](std::chrono::milliseconds span) {
    const auto end = std::chrono::steady_clock::now() + span;
    while (!watched.cause && std::chrono::steady_clock::now() < end) {
      wire::Control control = event("ir", std::string(500, 'r'));
      watched.connection->send(sealer.seal(control), FrameKind::must_arrive);
      pair.io.restart();
      pair.io.run_for(20ms);
    }
  };
  send_for(8 * kTimeout);
  EXPECT_FALSE(watched.cause) << "closed while the peer read: " << watched.why;
  EXPECT_LE(watched.connection->frames_waiting(), 2u) << "the kernel took the frames";

  reading = false;  // the read in flight completes; no other follows
  const auto stopped = std::chrono::steady_clock::now();
  send_for(20 * kTimeout);
  ASSERT_TRUE(watched.cause) << "still open after " << 20 * kTimeout.count() << " ms";
  EXPECT_EQ(*watched.cause, CloseCause::write_stalled);
  EXPECT_NE(watched.why.find("the peer stopped reading"), std::string::npos) << watched.why;
  EXPECT_GE(std::chrono::steady_clock::now() - stopped, 2 * kTimeout);
  EXPECT_LT(watched.connection->frames_waiting(), kMaxWaitingFrames)
      << "closed for the kernel's count, not the queue";
}

// ---- the UDP endpoint ----

TEST(DatagramEndpoint, HandsOverWhatPassesTheInspectorAndCountsTheRestByReason) {
  const wire::TrafficKey key = test_key();
  asio::io_context io;
  wire::DatagramSealer user(key, kTransportSession, 1), stranger(key, kTransportSession, 2);
  auto inspector = std::make_unique<wire::DatagramInspector>(kTransportSession);
  inspector->allow_sender(1, key, user.salt());
  DatagramEndpoint endpoint(io, udp::endpoint(asio::ip::make_address("127.0.0.1"), 0),
                            std::move(inspector));
  std::vector<std::pair<double, udp::endpoint>> received;
  endpoint.start([&](wire::Datagram&& datagram, const udp::endpoint& from, std::int64_t) {
    received.emplace_back(datagram.tool().position().x(), from);
  });
  udp::socket peer(io, udp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  const udp::endpoint to(asio::ip::make_address("127.0.0.1"), endpoint.port());
  const auto tool_sample = [](double x) {
    wire::Datagram datagram;
    datagram.mutable_tool()->mutable_position()->set_x(x);
    datagram.mutable_tool()->mutable_position()->set_y(0);
    datagram.mutable_tool()->mutable_position()->set_z(0);
    return datagram;
  };
  Bytes first;
  for (int i = 0; i < 5; ++i) {
    wire::Datagram datagram = tool_sample(i);
    const Bytes bytes = user.seal(datagram);
    if (i == 0) first = bytes;
    peer.send_to(asio::buffer(bytes), to);
  }
  wire::Datagram forged_datagram = tool_sample(9);
  Bytes forged = user.seal(forged_datagram);
  forged[forged.size() - 3] ^= 0x10;
  peer.send_to(asio::buffer(forged), to);                                // bad_tag
  peer.send_to(asio::buffer(Bytes(wire::kMaxDatagramBytes + 100)), to);  // oversized, seen whole
  peer.send_to(asio::buffer(Bytes(3000)), to);  // oversized, larger than the buffer
  wire::Datagram from_stranger = tool_sample(8);
  peer.send_to(asio::buffer(stranger.seal(from_stranger)), to);  // unknown_sender
  peer.send_to(asio::buffer(first), to);                         // replayed
  const wire::RejectionCounters& counters = endpoint.inspector().counters();
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (counters.accepted() + counters.rejected() < 10 && std::chrono::steady_clock::now() < end) {
    io.restart();
    io.run_for(5ms);
  }
  ASSERT_EQ(received.size(), 5u);
  for (std::size_t i = 0; i < received.size(); ++i) {
    EXPECT_EQ(received[i].first, static_cast<double>(i));
    EXPECT_EQ(received[i].second, peer.local_endpoint());
  }
  EXPECT_EQ(counters.accepted(), 5u);
  EXPECT_EQ(counters.count(wire::Rejection::bad_tag), 1u);
  EXPECT_EQ(counters.count(wire::Rejection::oversized), 2u);
  EXPECT_EQ(counters.count(wire::Rejection::unknown_sender), 1u);
  EXPECT_EQ(counters.count(wire::Rejection::replayed), 1u);
  EXPECT_EQ(counters.rejected(), 5u);

  // And the other way: sealed bytes out, as given.
  endpoint.send(first, peer.local_endpoint());
  Bytes echo(wire::kMaxDatagramBytes);
  const std::size_t n = peer.receive(asio::buffer(echo));
  echo.resize(n);
  EXPECT_EQ(echo, first);
  io.restart();
  io.poll();  // the send's completion, which counts it
  EXPECT_EQ(endpoint.sent(), 1u);
}

// ---- rate limits ----

TEST(SourceRateLimiter, FollowsATokenBucketPerAddressOnADrivenClock) {
  SourceRateLimiter limiter({.burst = 4, .first_burst = 4, .refill_per_s = 2, .max_sources = 2});
  const auto a = asio::ip::make_address("10.0.0.1"), b = asio::ip::make_address("10.0.0.2"),
             c = asio::ip::make_address("10.0.0.3");
  constexpr std::int64_t s = 1'000'000'000;
  // An independent model: tokens start at the burst, each failure takes one, refill 2/s.
  double tokens = 4;
  std::int64_t now = 0;
  std::mt19937 rng(5);
  int heard = 0, dropped = 0;
  for (int i = 0; i < 2000; ++i) {
    const std::int64_t step = static_cast<std::int64_t>(rng() % (s / 20));
    tokens = std::min(4.0, tokens + 2.0 * static_cast<double>(step) / static_cast<double>(s));
    now += step;
    const bool limited = limiter.limited(a, now);
    ASSERT_EQ(limited, tokens < 1) << "at " << now << " ns, model tokens " << tokens;
    if (limited) {
      ++dropped;
      continue;
    }
    ++heard;
    limiter.charge(a, now);
    tokens = std::max(0.0, tokens - 1);
  }
  // Over ~50 s, a source that always fails is heard about burst + 2/s times.
  const double seconds = static_cast<double>(now) / static_cast<double>(s);
  EXPECT_NEAR(heard, 4 + 2 * seconds, 2.0);
  EXPECT_GT(dropped, heard);
  // Other addresses are independent; a third evicts the one heard from longest ago.
  EXPECT_FALSE(limiter.limited(b, now));
  limiter.charge(b, now);
  EXPECT_EQ(limiter.sources(), 2u);
  limiter.charge(c, now + 1);
  EXPECT_EQ(limiter.sources(), 2u);
  EXPECT_FALSE(limiter.limited(a, now + 1))
      << "a was evicted: a new source starts with its first burst";
}

// A flood that rotates through 800 source addresses, one failing datagram each per round,
// 100 rounds a second for 5 s. Each new source starts with a small burst and all of them
// share one budget, so the datagrams inspected are bounded by that budget, not by the
// number of addresses. A proven source (it sent a valid datagram) is never limited by it.
TEST(SourceRateLimiter, RotatingSourceAddressesShareOneBudgetThatSparesAProvenSource) {
  const RateLimit limit{.burst = 64,
                        .first_burst = 4,
                        .refill_per_s = 16,
                        .all_sources_burst = 256,
                        .all_sources_refill_per_s = 256,
                        .max_sources = 256,
                        .max_proven = 16};
  SourceRateLimiter limiter(limit);
  const auto genuine = asio::ip::make_address("10.1.0.1");
  constexpr std::int64_t kRound = 10'000'000;  // 10 ms
  limiter.prove(genuine, 0);
  std::uint64_t inspected = 0, genuine_limited = 0;
  std::int64_t now = 0;
  for (int round = 0; round < 500; ++round, now += kRound) {
    for (std::uint32_t k = 0; k < 800; ++k) {
      const auto source = asio::ip::address_v4(0x0a020000u + k);
      if (limiter.limited(source, now)) continue;
      ++inspected;
      limiter.charge(source, now);
    }
    genuine_limited += limiter.limited(genuine, now);
  }
  const double seconds = static_cast<double>(now) * 1e-9;
  std::printf(
      "  400,000 failing datagrams from 800 rotating sources in %.0f s: %lu inspected (budget "
      "%.0f)\n",
      seconds, static_cast<unsigned long>(inspected),
      limit.all_sources_burst + limit.all_sources_refill_per_s * seconds);
  EXPECT_LE(static_cast<double>(inspected),
            limit.all_sources_burst + limit.all_sources_refill_per_s * seconds + 1);
  EXPECT_GE(static_cast<double>(inspected), limit.all_sources_refill_per_s * seconds * 0.9)
      << "the budget is spent";
  EXPECT_EQ(genuine_limited, 0u);
}

TEST(DatagramEndpoint, AFloodingSourceIsRateLimitedAndAnAdmittedPeerOnItsAddressLosesNothing) {
  const wire::TrafficKey key = test_key();
  asio::io_context io;
  wire::DatagramSealer user(key, kTransportSession, 1);
  auto inspector = std::make_unique<wire::DatagramInspector>(kTransportSession);
  inspector->allow_sender(1, key, user.salt());
  const RateLimit limit{.burst = 64, .refill_per_s = 16, .max_sources = 256};
  DatagramEndpoint endpoint(io, udp::endpoint(asio::ip::make_address("127.0.0.1"), 0),
                            std::move(inspector), limit);
  int received = 0;
  endpoint.start([&](wire::Datagram&&, const udp::endpoint&, std::int64_t) { ++received; });
  const udp::endpoint to(asio::ip::make_address("127.0.0.1"), endpoint.port());
  udp::socket peer(io, udp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  udp::socket attacker(io, udp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  endpoint.trust(peer.local_endpoint());
  std::mt19937 rng(9);
  constexpr int kGarbage = 20000, kSamples = 200;
  const auto started = std::chrono::steady_clock::now();
  for (int i = 0; i < kGarbage; ++i) {
    Bytes junk(40 + rng() % 200);
    for (auto& byte : junk) byte = static_cast<std::uint8_t>(rng());
    attacker.send_to(asio::buffer(junk), to);
    if (i % (kGarbage / kSamples) == 0) {
      wire::Datagram sample;
      sample.mutable_tool()->mutable_position()->set_x(i);
      peer.send_to(asio::buffer(user.seal(sample)), to);
    }
    if (i % 50 == 49) {  // let the endpoint read: the kernel's queue is finite
      io.restart();
      io.poll();
    }
  }
  const wire::RejectionCounters& counters = endpoint.inspector().counters();
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (counters.accepted() + counters.rejected() < kGarbage + kSamples &&
         std::chrono::steady_clock::now() < end) {
    io.restart();
    io.run_for(5ms);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  EXPECT_EQ(received, kSamples) << "an admitted peer's datagram was lost or refused";
  EXPECT_EQ(counters.accepted() + counters.rejected(),
            static_cast<std::uint64_t>(kGarbage + kSamples))
      << "the kernel dropped some: the test sends faster than it reads";
  const std::uint64_t inspected_garbage =
      counters.rejected() - counters.count(wire::Rejection::rate_limited);
  std::printf(
      "  %d garbage datagrams in %.2f s: %lu inspected, %lu dropped unread (rate_limited); %d "
      "samples of an "
      "admitted peer on the same address all accepted\n",
      kGarbage, seconds, static_cast<unsigned long>(inspected_garbage),
      static_cast<unsigned long>(counters.count(wire::Rejection::rate_limited)), received);
  EXPECT_LE(static_cast<double>(inspected_garbage), limit.burst + limit.refill_per_s * seconds + 1);
  EXPECT_GE(counters.count(wire::Rejection::rate_limited),
            static_cast<std::uint64_t>(kGarbage) - inspected_garbage);
}

// What the soak found: frames sent in a burst over the server's jittered TCP link were
// delivered by timers that could expire out of order (each deadline was counted from its
// own reading of the clock, and equal deadlines fire in any order), so a client received
// an event sealed with its slot's key before the Welcome that gave it the slot.
TEST(DelayedDelivery, AnOrderedLinkWithJitterDeliversABurstInOrder) {
  asio::io_context io;
  LinkDelay link({.delay_ms = 0, .jitter_ms = 10, .seed = 16}, true);
  std::vector<int> delivered;
  constexpr int kMessages = 5000;  // sent as fast as the loop goes: a burst, many within one jitter
  for (int i = 0; i < kMessages; ++i)
    ASSERT_TRUE(deliver_over(link, io, monotonic_now_ns(),
                             [&delivered, i](std::int64_t) { delivered.push_back(i); }));
  io.run();
  ASSERT_EQ(delivered.size(), static_cast<std::size_t>(kMessages));
  for (int i = 0; i < kMessages; ++i)
    ASSERT_EQ(delivered[static_cast<std::size_t>(i)], i) << "delivered out of order";
}

}  // namespace
}  // namespace cohaptic::net
