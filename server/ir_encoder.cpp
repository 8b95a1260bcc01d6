#include "server/ir_encoder.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <exception>
#include <future>
#include <iterator>
#include <map>
#include <utility>

#include "common/util/monotonic_clock.h"
#include "proto/wire/header.h"
#include "proto/wire/ir_convert.h"

namespace cohaptic {

IrEncoder::IrEncoder(int users, record::SessionRecorder* recorder, LoopStatistics& statistics)
    : recorder_(recorder), statistics_(statistics), streams_(static_cast<std::size_t>(users)) {}

IrEncoder::~IrEncoder() { stop(); }

namespace {

// Whether the IR travels whole (not as compliance rows, each of which builds on the last).
bool travels_whole(const BuiltIr& built) { return built.send && !built.as_sent; }

}  // namespace

void IrEncoder::encode(std::vector<BuiltIr>& irs, Outbox& outbox) {
  record(irs, frame(irs, outbox));
}

std::vector<IrEncoder::ToRecord> IrEncoder::frame(std::vector<BuiltIr>& irs, Outbox& outbox) {
  if (irs.empty()) return {};
  const std::int64_t start_ns = monotonic_now_ns();
  // An IR that travels whole and is followed by another of its user's that does too is
  // superseded: it is recorded, not sent; a fresh start of the stream passes to the next.
  std::vector<char> superseded(irs.size(), 0);
  std::map<int, bool> next_whole;  // per user, scanning back
  for (std::size_t i = irs.size(); i-- > 0;) {
    bool& next = next_whole[irs[i].user];
    superseded[i] = travels_whole(irs[i]) && next;
    next = travels_whole(irs[i]);
  }
  std::map<int, bool> carried_fresh;
  for (std::size_t i = 0; i < irs.size(); ++i) {
    bool& carried = carried_fresh[irs[i].user];
    if (superseded[i])
      carried = carried || irs[i].fresh;
    else
      irs[i].fresh = std::exchange(carried, false) || irs[i].fresh;
  }
  if (std::any_of(irs.begin(), irs.end(), [](const BuiltIr& built) { return built.announces_p1; }))
    outbox.protocol_switch = wire::P1;
  // Each user's IRs to send, in order, grouped by user in the order they first appear.
  std::vector<std::vector<std::size_t>> by_user;
  std::map<int, std::size_t> group_of_user;
  std::uint64_t skipped = 0;
  for (std::size_t i = 0; i < irs.size(); ++i) {
    if (superseded[i]) ++skipped;
    if (!irs[i].send || superseded[i]) continue;
    const auto [group, added] = group_of_user.try_emplace(irs[i].user, by_user.size());
    if (added) by_user.emplace_back();
    by_user[group->second].push_back(i);
  }
  // The users' streams are independent: each user's IRs are framed on a thread of its own
  // (the first user's on this one), so that one user's compression does not hold back the
  // IR of another.
  std::vector<ToRecord> to_record(recorder_ ? irs.size() : 0);
  std::vector<UserFrames> frames(by_user.size());
  {
    std::vector<std::future<void>> others;
    for (std::size_t g = 1; g < by_user.size(); ++g)
      others.push_back(std::async(std::launch::async,
                                  [&, g] { frames[g] = frame_user(irs, by_user[g], to_record); }));
    if (!by_user.empty()) frames[0] = frame_user(irs, by_user[0], to_record);
    for (std::future<void>& other : others) other.get();
  }
  std::uint64_t sent = 0, bytes = 0;
  for (UserFrames& user : frames) {
    sent += user.frames.size();
    bytes += user.bytes;
    std::move(user.frames.begin(), user.frames.end(), std::back_inserter(outbox.irs));
  }
  statistics_.record_irs_encoded(monotonic_now_ns() - start_ns, sent, bytes, skipped);
  return to_record;
}

IrEncoder::UserFrames IrEncoder::frame_user(const std::vector<BuiltIr>& irs,
                                            std::span<const std::size_t> indices,
                                            std::vector<ToRecord>& to_record) {
  UserFrames user;
  for (const std::size_t i : indices) {
    const BuiltIr& built = irs[i];
    // What travels: the compliance rows, or the IR whole (kept for the recording).
    std::optional<wire::IntermediateRepresentation> whole;
    if (!built.as_sent) whole = wire::to_wire(built.built->ir);
    wire::Control control;
    try {
      if (built.streamed)
        *control.mutable_compressed_ir() = streams_[static_cast<std::size_t>(built.user)].compress(
            built.as_sent ? wire::to_wire(*built.as_sent) : *whole, built.fresh);
      else
        *control.mutable_ir() = built.as_sent ? wire::to_wire(*built.as_sent) : *whole;
    } catch (const std::exception& e) {
      spdlog::error("user {}'s IR (epoch {}) not sent: {}; the next starts its stream afresh",
                    built.user, built.built->ir.epoch, e.what());
      if (recorder_) to_record[i].whole = std::move(whole);
      std::lock_guard lock(mutex_);
      restarts_.push_back(built.user);
      continue;
    }
    // The recording keeps the IR whole (M~ as built), whatever form it travels in: the
    // block itself when it holds the IR whole (recorded blocks open in order, as a
    // client's do), else the IR.
    if (recorder_) {
      if (built.streamed && !built.as_sent)
        to_record[i].block = control.compressed_ir();
      else
        to_record[i].whole = std::move(whole);
    }
    user.bytes +=
        built.streamed ? control.compressed_ir().ByteSizeLong() : control.ir().ByteSizeLong();
    user.frames.push_back({built.user, std::move(control), built.streamed});
  }
  return user;
}

void IrEncoder::record(const std::vector<BuiltIr>& irs, std::vector<ToRecord> to_record) {
  if (!recorder_) return;
  for (std::size_t i = 0; i < irs.size(); ++i) {
    const BuiltIr& built = irs[i];
    ToRecord& kept = to_record[i];
    if (kept.block)
      recorder_->ir_block(built.time_ns, static_cast<std::uint32_t>(built.user), *kept.block,
                          built.repeat);
    else
      recorder_->ir(built.time_ns, kept.whole ? *kept.whole : wire::to_wire(built.built->ir),
                    built.repeat);
  }
}

void IrEncoder::start(std::function<void(Outbox&&)> send) {
  stop();
  send_ = std::move(send);
  stopping_ = false;
  thread_ = std::thread([this] { run(); });
}

void IrEncoder::post(std::vector<BuiltIr> irs) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return queue_.size() < kMaxQueuedSteps; });
  queue_.push_back(std::move(irs));
  changed_.notify_all();
}

void IrEncoder::stop() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

std::vector<int> IrEncoder::take_restarts() {
  std::lock_guard lock(mutex_);
  return std::exchange(restarts_, {});
}

void IrEncoder::run() {
  for (;;) {
    std::vector<BuiltIr> irs;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, and nothing left
      // Every step waiting, at once: a user's IR that a newer one replaces is not sent.
      for (std::vector<BuiltIr>& step : queue_)
        std::move(step.begin(), step.end(), std::back_inserter(irs));
      queue_.clear();
    }
    changed_.notify_all();  // room for post()
    // The frames leave before the recording is written, so that no IR of the batch waits
    // for the recording of those before it.
    Outbox outbox;
    std::vector<ToRecord> to_record = frame(irs, outbox);
    if (!outbox.empty()) send_(std::move(outbox));
    record(irs, std::move(to_record));
  }
}

}  // namespace cohaptic
