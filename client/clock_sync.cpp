#include "client/clock_sync.h"

#include "common/util/monotonic_clock.h"
#include "proto/wire/header.h"

namespace cohaptic {

ClockSync::ClockSync(asio::io_context& io, std::function<void(wire::Datagram&)> send_ping)
    : timer_(io), send_ping_(std::move(send_ping)) {}

void ClockSync::start() { schedule(); }

void ClockSync::stop() { timer_.cancel(); }

void ClockSync::restart() {
  estimate_ = ClockOffsetEstimator();
  ping();
}

void ClockSync::ping() {
  wire::Datagram datagram;
  datagram.mutable_ping()->set_client_send_ns(monotonic_now_ns());
  send_ping_(datagram);
}

void ClockSync::schedule() {
  timer_.expires_after(kPingInterval);
  timer_.async_wait([this](std::error_code error) {
    if (error) return;
    ping();
    schedule();
  });
}

void ClockSync::on_pong(const wire::ClockPong& pong, std::int64_t arrival_ns) {
  estimate_.add(pong.client_send_ns(), pong.server_receive_ns(), pong.server_send_ns(), arrival_ns);
}

void ClockSync::observe(std::int64_t sender_time_ns, std::int64_t arrival_ns) {
  if (estimate_.valid()) one_way_ns_.record(arrival_ns - estimate_.to_client(sender_time_ns));
}

void ClockSync::add_to_report(nlohmann::json& report) const {
  const auto ms = [](std::int64_t ns) { return static_cast<double>(ns) * 1e-6; };
  report["clock"] = {{"offset_ms", ms(estimate_.offset_ns())},
                     {"round_trip_ms", ms(estimate_.round_trip_ns())}};
  report["one_way_delay_ms"] = {{"p50", ms(one_way_ns_.quantile(0.5))},
                                {"p99", ms(one_way_ns_.quantile(0.99))},
                                {"samples", one_way_ns_.count()}};
}

}  // namespace cohaptic
