// ConnectionHandler: the server's side of the network, run by the I/O thread. It owns
//   - the TCP acceptor and one participant per control connection (net::FramedConnection):
//     the greeting with its challenge, join (a free user slot, the Welcome), leave (the
//     slot and its tool released), events to every user;
//   - the UDP endpoint (net::DatagramEndpoint): tool samples in (the newest of each slot
//     to ToolInputs, and relayed to the other users), clock pings answered with pongs;
//   - the sending of each step's Outbox (IRs over TCP, keep-alives and forces over UDP);
//     nothing goes to a user over UDP before a datagram has come from it (its first is sent
//     once it has the welcome, and with it the key the server's datagrams are opened with);
//   - the injected shift delay: per participant, one LinkDelay per link and direction (to
//     the client over UDP and over TCP, from the client over UDP), applied where a message
//     leaves or enters the process;
//   - the keys: every slot's traffic key and the joining key, derived from the session key
//     (wire/traffic_keys.h). A connection's frames are opened with the key of the sender
//     they name: before its join, any slot's or the joining key; after it, its slot's only.
//     What the server sends a user is sealed with that user's key;
//   - the limits: at most the scene's network.max_participants users at once, each sending
//     at most kUserDatagramsPerTick datagrams a tick of its haptic loop; at most
//     kMaxUnjoinedPerSource connections that have not joined from one address and
//     kMaxUnjoinedConnections in all (a new one past either closes the oldest), each closed
//     if it has not joined within kJoinTimeout; a user that stops reading is dropped by its
//     connection (newest-wins IRs, then net::kWriteTimeout);
//   - its counters, for the status line and the report.
// It decides slots and what to relay; sealing is the codec's (wire::FrameSealer,
// wire::DatagramSealer), the sockets are net/'s. With --record it records the datagrams
// it accepts, the joins and leaves and the users' status reports (ClientStatus, also handed
// to on_client_status: the live view's panel). Everything here runs on the I/O thread,
// except the counters' readers noted below.
#pragma once

#include <array>
#include <asio.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "net/datagram_endpoint.h"
#include "net/framed_connection.h"
#include "net/token_bucket.h"
#include "proto/record/session_recorder.h"
#include "proto/wire/rejection.h"
#include "proto/wire/sealer.h"
#include "proto/wire/session_key.h"
#include "server/outbox.h"
#include "server/serve_options.h"
#include "server/tool_inputs.h"

namespace cohaptic {

/// How long a slot's sender stays allowed after its user left: samples sent just before
/// the goodbye may still be in flight, and are accepted and ignored rather than counted
/// as hostile.
inline constexpr std::int64_t kLeftSenderGrace_ms = 500;
/// A connection that has not joined within this time is closed.
inline constexpr std::chrono::seconds kJoinTimeout{10};
/// After an accept() that failed (out of file descriptors, say), the listener waits this
/// long and accepts again: it never stops, and never spins on a failure that persists.
inline constexpr std::chrono::milliseconds kAcceptRetry{100};
/// Connections that have not joined, at most, from one source address and in all: a new
/// one past either bound closes the oldest unjoined one (of that source, or of all).
inline constexpr std::size_t kMaxUnjoinedPerSource = 4;
inline constexpr std::size_t kMaxUnjoinedConnections = 64;
/// The kernel's send buffer of a control connection, fixed rather than grown without a
/// say: with kMaxWaitingFrames, what a user that stops reading can hold up is bounded, and
/// its writes stall (net::kWriteTimeout) within seconds. A few IRs' worth at any link speed.
inline constexpr int kControlSendBufferBytes = 1 << 20;
/// The largest frame body a client may send: its frames (Join, Event, Bye, ClientStatus) are
/// small, and a frame declared larger is refused (oversized) before its body is buffered.
/// Until it has joined, a connection may send a Join only (about 100 bytes): kMaxJoinFrameBytes,
/// so that the unjoined connections together cannot make the server hold more than a few KiB.
inline constexpr std::size_t kMaxClientFrameBytes = std::size_t{64} << 10;
inline constexpr std::size_t kMaxJoinFrameBytes = 1024;
/// The datagrams a joined user may send a second: this many times its haptic rate (a
/// tool sample a tick, and its clock's pings), with a second's samples banked for a burst
/// after a stall. Past it they are dropped before anything uses, relays or records them
/// (over_budget). A join asking for a rate above kMaxClientHapticRateHz is refused.
inline constexpr double kUserDatagramsPerTick = 2;
inline constexpr double kMaxClientHapticRateHz = 10000;

struct ConnectionCounters {
  std::uint64_t datagrams_sent = 0, datagrams_relayed = 0;
  std::uint64_t datagrams_over_budget = 0;        ///< a user's, past kUserDatagramsPerTick a tick
  std::uint64_t datagrams_dropped_by_kernel = 0;  ///< the receive queue was full (SO_RXQ_OVFL)
  std::uint64_t frames_sent = 0, frames_rejected = 0, frames_dropped = 0;
  std::array<std::uint64_t, wire::kRejectionCount> frames_rejected_by_reason{};
  std::uint64_t dropped_to_clients = 0, dropped_from_clients = 0;  ///< by the injected loss
  std::uint64_t connections = 0;                                   ///< accepted
  std::uint64_t joins = 0;                                         ///< welcomed
  std::uint64_t joins_refused = 0;  ///< session full, slot taken, or a key for another slot
  std::uint64_t unjoined_evicted =
      0;                            ///< closed before joining: a newer connection needed the room
  std::uint64_t join_timeouts = 0;  ///< closed: not joined within kJoinTimeout
  std::uint64_t accept_errors =
      0;  ///< accept() failed (e.g. out of file descriptors): tried again after kAcceptRetry
  std::uint64_t write_stalls = 0;     ///< closed: the user stopped reading (write timeout)
  std::uint64_t queue_overflows = 0;  ///< closed: frames that must arrive piled up unread
};

class ConnectionHandler {
 public:
  /// Binds TCP and UDP on `options.host`:`options.port` (the UDP port is the TCP one).
  /// `welcome` carries everything a joining user is told but its slot and the users' names
  /// (one entry per slot, with tool names). `max_participants`: users joined at once, at
  /// most (0: one per slot). `recorder` may be null. Throws std::system_error if a socket
  /// cannot be bound.
  ConnectionHandler(asio::io_context& io, const ServeOptions& options, wire::Welcome welcome,
                    const wire::SessionKey& key, std::uint64_t session, int max_participants,
                    ToolInputs& tools, record::SessionRecorder* recorder);
  ~ConnectionHandler();
  ConnectionHandler(const ConnectionHandler&) = delete;
  ConnectionHandler& operator=(const ConnectionHandler&) = delete;

  using StatusHandler =
      std::function<void(int slot, const std::string& user, const wire::ClientStatus& status)>;
  /// Where the users' status reports go (on the I/O thread); set before start().
  void on_client_status(StatusHandler handler) { on_status_ = std::move(handler); }

  /// Starts accepting connections and receiving datagrams.
  void start();
  /// Sends a step's messages (stamped and sealed now) to the users now in their slots.
  void send(Outbox outbox);
  /// Tells every user goodbye with `reason`, and accepts no more connections.
  void say_goodbye(const std::string& reason);
  /// Closes every connection and the UDP socket.
  void close_all(const std::string& why);

  std::uint16_t tcp_port() const { return tcp_port_; }
  std::uint16_t udp_port() const { return udp_.port(); }
  int users() const;
  int slots() const { return static_cast<int>(slots_.size()); }
  /// On the I/O thread, or after it stopped.
  ConnectionCounters counters() const;
  /// From any thread.
  const wire::RejectionCounters& datagram_counters() const { return udp_.inspector().counters(); }

 private:
  struct Participant;
  using ParticipantPtr = std::shared_ptr<Participant>;

  void accept();
  void make_room_for_unjoined(const asio::ip::address& source);
  void closed(const ParticipantPtr& participant, net::CloseCause cause, const std::string& why);
  const wire::TrafficKey* key_for(const Participant& participant, std::uint32_t sender) const;
  void handle_control(const ParticipantPtr& participant, const wire::Control& control);
  void join(const ParticipantPtr& participant, const wire::Control& control);
  int take_slot(const ParticipantPtr& participant, const wire::Join& request, std::uint32_t sender);
  void client_status(const Participant& participant, const wire::ClientStatus& status);
  void leave(const ParticipantPtr& participant, const std::string& why);
  void reject_frame(const ParticipantPtr& participant, wire::Rejection reason,
                    const std::string& why);
  void broadcast_event(const std::string& kind, const std::string& text,
                       const record::EventUser& user);
  void send_bytes(const ParticipantPtr& participant, std::vector<std::uint8_t> bytes,
                  net::FrameKind kind, bool frame);
  void send_control(const ParticipantPtr& participant, wire::Control& control,
                    bool newest_wins = false);
  void send_error(const ParticipantPtr& participant, const std::string& code,
                  const std::string& text);
  void send_datagram(Participant& participant, wire::Datagram& datagram);
  void receive_datagram(wire::Datagram&& datagram, std::int64_t arrival_ns);
  void handle_datagram(const wire::Datagram& datagram, int slot, std::int64_t arrival_ns);
  /// Logs a warning about hostile or broken input at most once a second (the counters keep the
  /// rest).
  void warn_throttled(const std::string& message);
  /// The injected shift delay on every link from now on, and for users who join later (a
  /// switched condition, from an outbox).
  void set_link_delay(const LinkDelaySettings& settings);

  asio::io_context& io_;
  const ServeOptions& options_;
  wire::Welcome welcome_;
  std::vector<wire::TrafficKey> slot_keys_;  ///< by slot
  wire::TrafficKey joining_key_;
  std::uint64_t session_;
  int max_participants_;
  ToolInputs& tools_;
  record::SessionRecorder* recorder_;
  asio::ip::tcp::acceptor acceptor_;
  asio::steady_timer accept_retry_;
  std::uint16_t tcp_port_ = 0;
  net::DatagramEndpoint udp_;
  std::vector<ParticipantPtr> participants_;  // every connection
  std::vector<ParticipantPtr> slots_;         // joined users, by slot
  ConnectionCounters counters_;
  std::int64_t last_warning_ns_ = 0;
  std::uint64_t warnings_held_ = 0;
  StatusHandler on_status_;
  LinkDelaySettings link_delay_;  // options_.shift until a condition switches it
};

}  // namespace cohaptic
