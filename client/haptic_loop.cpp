#include "client/haptic_loop.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <cmath>
#include <limits>

#include "common/util/monotonic_clock.h"

namespace cohaptic {
namespace {

// Sleeps until `deadline_ns` of the session clock (monotonic_clock.h), whose steady_clock
// is CLOCK_MONOTONIC.
void sleep_until_monotonic(std::int64_t deadline_ns) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline_ns / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(deadline_ns % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}

}  // namespace

std::uint64_t skip_missed_deadlines(std::int64_t& deadline, std::int64_t woke,
                                    std::int64_t period) {
  if (woke < deadline + period) return 0;
  const auto missed = static_cast<std::uint64_t>((woke - deadline) / period);
  deadline += static_cast<std::int64_t>(missed) * period;
  return missed;
}

IrSlot make_ir_slot(std::unique_ptr<const PreparedIR> ir, std::int64_t arrival_ns) {
  auto state = std::make_unique<EvaluationState>(make_evaluation_state(*ir));
  auto alone_state = std::make_unique<EvaluationState>(*state);
  const bool body_moves = evaluation_moves_the_body(*state);
  const bool measures_elapsed = evaluation_measures_elapsed_time(*state);
  return IrSlot{std::move(ir), std::move(state), std::move(alone_state),
                arrival_ns,    body_moves,       measures_elapsed};
}

HapticClock HapticClock::monotonic() {
  return {[](void*) { return monotonic_now_ns(); },
          [](void*, std::int64_t deadline_ns) { sleep_until_monotonic(deadline_ns); }, nullptr};
}

bool lock_process_memory() {
  static const bool locked = mlockall(MCL_CURRENT | MCL_FUTURE) == 0;  // once, thread-safe
  return locked;
}

bool enter_realtime(int priority) {
  sched_param param{};
  param.sched_priority = priority;
  const bool fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
  return fifo && lock_process_memory();
}

HapticLoop::HapticLoop(HapticDevice& device, HapticChannels& channels, HapticLoopSettings settings,
                       HapticClock clock)
    : device_(device),
      channels_(channels),
      settings_(settings),
      protocol_(settings.protocol),
      remote_buffers_{RemoteToolBuffer(settings.playout,
                                       static_cast<std::int64_t>(settings.playout_delay_s * 1e9)),
                      RemoteToolBuffer(settings.playout,
                                       static_cast<std::int64_t>(settings.playout_delay_s * 1e9)),
                      RemoteToolBuffer(settings.playout,
                                       static_cast<std::int64_t>(settings.playout_delay_s * 1e9)),
                      RemoteToolBuffer(settings.playout,
                                       static_cast<std::int64_t>(settings.playout_delay_s * 1e9))},
      passivity_(settings.passivity_mass_kg, settings.force_limit),
      clock_(clock) {}

bool HapticLoop::take_in_server_updates() {
  const bool p1 = protocol_ == HapticProtocol::p1;
  const bool in_use_new = p1 ? channels_.ir.update() : channels_.force.update();
  channels_.protocol.update();
  const ProtocolChange& change = channels_.protocol.front();
  if (change.since_ns == 0 || change.protocol == protocol_) return in_use_new;
  // A switch waits: the other protocol's channel is taken in too, and the loop changes over
  // once what arrived after the switch is there (what arrived before it is not enough).
  const bool ready =
      p1 ? (channels_.force.update(),
            channels_.force.front().valid && channels_.force.front().arrival_ns >= change.since_ns)
         : (channels_.ir.update(),
            channels_.ir.front().ir && channels_.ir.front().arrival_ns >= change.since_ns);
  if (!ready) return in_use_new;
  protocol_ = change.protocol;
  ++metrics_.protocol_switches;
  return true;
}

Eigen::Vector3d HapticLoop::compute_force(std::int64_t now, const Eigen::Vector3d& own,
                                          TickRecord& record) {
  std::int64_t age = std::numeric_limits<std::int64_t>::max();
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  record.remotes.fill(Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  record.protocol = protocol_;
  if (protocol_ == HapticProtocol::p1) {
    const IrSlot& slot = channels_.ir.front();
    if (slot.ir) {
      // Its age runs from its arrival or its last confirmation: the confirmations of a newer
      // IR (still on its way) do not make the one in use older than that.
      const IrConfirmation& confirmed = channels_.confirmation.front();
      if (confirmed_ir_ != slot.ir.get()) {
        confirmed_ir_ = slot.ir.get();
        confirmed_ns_ = slot.arrival_ns;
      }
      if (confirmed.epoch == slot.ir->ir.epoch)
        confirmed_ns_ = std::max(confirmed_ns_, confirmed.arrival_ns);
      age = now - confirmed_ns_;
      const IntermediateRepresentation& ir = slot.ir->ir;
      std::array<Eigen::Vector3d, kMaxUsers - 1> remotes;
      const std::size_t count =
          std::min<std::size_t>(static_cast<std::size_t>(remote_count(ir)), remotes.size());
      for (std::size_t r = 0; r < count; ++r) {
        const PlayoutQuery remote =
            remote_buffers_[static_cast<std::size_t>(remote_user(ir, static_cast<int>(r)) %
                                                     kMaxUsers)]
                .at(now);
        remotes[r] = remote.valid
                         ? remote.position
                         : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
        record.remotes[r] = remotes[r];
      }
      record.remote_count = static_cast<std::uint8_t>(count);
      // dt: the nominal period, or for a body whose force is a velocity the time since the
      // last evaluation's tick; recorded, so that a replay reproduces the force bit for bit.
      const double dt = slot.measures_elapsed && last_evaluated_ns_ > 0 && now > last_evaluated_ns_
                            ? 1e-9 * static_cast<double>(now - last_evaluated_ns_)
                            : 1 / settings_.rate_hz;
      last_evaluated_ns_ = now;
      const ForceSample sample = evaluate_force_in_turn(
          *slot.ir, *slot.state, carry_, own, std::span(remotes.data(), count), dt, record.buttons);
      // A sphere contact solve that could not finish inside the tick has no answer: hold the
      // last one and count the tick.
      if (sample.flags & kContactUnresolved) {
        force = last_evaluated_;
        ++metrics_.contact_unresolved;
      } else {
        force = sample.force;
        last_evaluated_ = force;
      }
      record.flags = sample.flags;
      record.ir_epoch = ir.epoch;
      record.dt = dt;
      // The coupling figure (the force without the remote tools) needs a second evaluation,
      // which would advance a dynamic body's state a second time: static bodies only. A sphere
      // body's contact solve is no body state: the second evaluation keeps one of its own.
      const bool static_body = !slot.body_moves;
      // Measured only in contact: a user that passed by a static body without touching it
      // (e.g. on its way to a mass-spring object lying on it) measured nothing. A home-spring
      // body's users never couple (each feels its own vertex's springs): nothing to measure.
      const bool couples =
          static_body && !std::holds_alternative<HomeSpringPatch>(slot.ir->ir.body);
      metrics_.coupling_measured =
          metrics_.coupling_measured || (couples && (sample.flags & kInContact));
      if (count > 0 && (sample.flags & kInContact) && static_body) {
        const ForceSample alone = evaluate_force(*slot.ir, *slot.alone_state, own, {}, dt);
        // A solve past its budget has no force to compare (the tick held the last one).
        if (!((sample.flags | alone.flags) & kContactUnresolved))
          metrics_.peak_coupling =
              std::max(metrics_.peak_coupling, (sample.force - alone.force).norm());
      }
    }
  } else {
    const ForceSlot& slot = channels_.force.front();
    if (slot.valid) {
      age = now - slot.arrival_ns;
      force = slot.force;
      record.ir_epoch = slot.epoch;
    }
  }
  if (age != std::numeric_limits<std::int64_t>::max()) {
    metrics_.ir_age_ns.record(age);
    record.ir_age_ns = age;
  }
  record.evaluated = force;

  // Stale data fades out.
  const double age_s = static_cast<double>(age) * 1e-9;
  float fade = 1;
  if (age_s > settings_.max_age_s)
    fade =
        static_cast<float>(std::max(0.0, 1.0 - (age_s - settings_.max_age_s) / settings_.fade_s));
  record.fade = fade;
  metrics_.fades.tick(fade, force.squaredNorm() > 0, 1 / settings_.rate_hz);
  force *= static_cast<double>(fade);
  return force;
}

void HapticLoop::publish_progress(double elapsed_s, bool finished) {
  channels_.progress.back() = {metrics_.ticks, metrics_.missed_deadlines, metrics_.clamped,
                               elapsed_s,      metrics_.peak_force,       metrics_.fades,
                               finished};
  channels_.progress.publish();
}

void HapticLoop::run(const std::atomic<bool>& stop) {
  if (settings_.realtime) {
    metrics_.realtime = enter_realtime(80);
    channels_.events.push(
        {metrics_.realtime ? HapticEventKind::started_realtime : HapticEventKind::realtime_refused,
         now(), 0});
  }
  const auto period = static_cast<std::int64_t>(1e9 / settings_.rate_hz);
  const std::int64_t start = now();
  std::int64_t deadline = start + period;
  std::int64_t last_woke = 0;
  std::uint64_t epoch_in_use = 0;
  while (!stop.load(std::memory_order_relaxed)) {
    clock_.sleep_until_ns(clock_.context, deadline);
    const std::int64_t woke = now();
    if (last_woke) metrics_.period_ns.record(woke - last_woke);
    last_woke = woke;
    metrics_.missed_deadlines += skip_missed_deadlines(deadline, woke, period);
    deadline += period;
    const double time_s = static_cast<double>(woke - start) * 1e-9;
    if ((settings_.duration_s > 0 && time_s >= settings_.duration_s) || device_.finished(time_s))
      break;

    const DeviceState state = device_.read(time_s);
    channels_.own_samples.push({woke, state.position, state.buttons, state.valid});
    while (const auto remote = channels_.remote_samples.pop())
      remote_buffers_[remote->user % kMaxUsers].add(remote->sample_time_ns, remote->arrival_ns,
                                                    remote->position, remote->valid);
    if (take_in_server_updates()) ++metrics_.ir_switches;
    channels_.confirmation.update();

    TickRecord record;
    record.time_ns = woke;
    record.own = state.position;
    record.buttons = state.buttons;
    record.own_valid = state.valid;
    Eigen::Vector3d force =
        state.valid ? compute_force(woke, state.position, record) : Eigen::Vector3d::Zero();
    if (protocol_ == HapticProtocol::p1 && record.ir_epoch != epoch_in_use) {
      if (epoch_in_use != 0)
        metrics_.largest_step_on_ir_switch =
            std::max(metrics_.largest_step_on_ir_switch, (force - last_force_).norm());
      epoch_in_use = record.ir_epoch;
    }
    if (!force.allFinite()) {
      force.setZero();
      ++metrics_.non_finite;
      channels_.events.push({HapticEventKind::non_finite, woke, record.ir_epoch});
    }
    if (settings_.passivity_control) {
      if (state.valid && state.position.allFinite()) {
        force = passivity_.filter(time_s, state.position, force);  // limited inside
      } else {
        passivity_.interrupt();  // this tick outputs zero, not what the controller last booked
      }
    }
    const double magnitude = force.norm();
    if (magnitude > settings_.force_limit) {
      force *= settings_.force_limit / magnitude;
      ++metrics_.clamped;
    }
    device_.write_force(force, time_s);
    last_force_ = force;
    metrics_.peak_force = std::max(metrics_.peak_force, force.norm());
    record.force = force;
    if (channels_.tracing.load(std::memory_order_relaxed)) channels_.trace.push(record);
    ++metrics_.ticks;
    publish_progress(time_s, false);
  }
  device_.write_force(Eigen::Vector3d::Zero(), static_cast<double>(now() - start) * 1e-9);
  metrics_.elapsed_s = static_cast<double>(now() - start) * 1e-9;
  publish_progress(metrics_.elapsed_s, true);
}

}  // namespace cohaptic
