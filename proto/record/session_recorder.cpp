#include "proto/record/session_recorder.h"

#include <spdlog/spdlog.h>

#include "common/util/error.h"
#include "proto/record/mcap_writer.h"

namespace cohaptic::record {

SessionRecorder::SessionRecorder(const std::filesystem::path& file) : file_(file) {
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  writer_ = std::make_unique<McapWriter>(file);
  const auto channel = [this](const google::protobuf::Descriptor* descriptor, const char* name) {
    return writer_->add_channel(writer_->add_protobuf_schema(descriptor), name);
  };
  config_ = channel(SessionConfig::descriptor(), topic::kConfig);
  datagrams_ = channel(ReceivedDatagram::descriptor(), topic::kDatagramsIn);
  ir_ = channel(RecordedIr::descriptor(), topic::kIr);
  haptic_ = channel(HapticTick::descriptor(), topic::kHaptic);
  steps_ = channel(SimulationStep::descriptor(), topic::kSteps);
  events_ = channel(SessionEvent::descriptor(), topic::kEvents);
  client_status_ = channel(ReceivedClientStatus::descriptor(), topic::kClientStatus);
  view_scene_ = channel(view::Scene::descriptor(), topic::kViewScene);
  view_frames_ = channel(view::Frame::descriptor(), topic::kViewFrames);
  writer_->flush();
}

SessionRecorder::~SessionRecorder() { close(); }

void SessionRecorder::write(std::uint16_t channel, std::int64_t time_ns,
                            const google::protobuf::MessageLite& message) {
  std::lock_guard lock(mutex_);
  if (failed_ || !writer_ || writer_->is_closed()) return;
  try {
    const auto time = static_cast<std::uint64_t>(std::max<std::int64_t>(time_ns, 0));
    writer_->write(channel, ++sequence_, time, time, message);
  } catch (const Error& e) {
    failed_ = true;
    spdlog::error("recording stopped (the session goes on): {}", e.what());
  }
}

void SessionRecorder::config(const SessionConfig& config) {
  write(config_, config.start_time_ns(), config);
  std::lock_guard lock(mutex_);
  if (!failed_) writer_->flush();
}

void SessionRecorder::datagram_in(std::int64_t receive_ns, const wire::Datagram& datagram) {
  ReceivedDatagram record;
  record.set_receive_time_ns(receive_ns);
  *record.mutable_datagram() = datagram;
  write(datagrams_, receive_ns, record);
}

void SessionRecorder::ir(std::int64_t time_ns, const wire::IntermediateRepresentation& ir,
                         bool repeat, const WarmStart* warm_start) {
  RecordedIr record;
  record.set_time_ns(time_ns);
  record.set_repeat(repeat);
  *record.mutable_ir() = ir;
  if (warm_start) *record.mutable_warm_start() = *warm_start;
  write(ir_, time_ns, record);
}

void SessionRecorder::ir_block(std::int64_t time_ns, std::uint32_t stream,
                               const wire::CompressedIr& block, bool repeat,
                               const WarmStart* warm_start) {
  RecordedIr record;
  record.set_time_ns(time_ns);
  record.set_repeat(repeat);
  *record.mutable_compressed_ir() = block;
  if (warm_start) *record.mutable_warm_start() = *warm_start;
  record.set_stream(stream);
  write(ir_, time_ns, record);
}

void SessionRecorder::tick(const HapticTick& tick) { write(haptic_, tick.time_ns(), tick); }

void SessionRecorder::step(const SimulationStep& step) { write(steps_, step.time_ns(), step); }

void SessionRecorder::event(std::int64_t time_ns, const std::string& kind, const std::string& text,
                            const std::optional<EventUser>& user) {
  SessionEvent record;
  record.set_time_ns(time_ns);
  record.set_kind(kind);
  record.set_text(text);
  if (user) {
    record.set_user(user->name);
    record.set_slot(user->slot);
  }
  write(events_, time_ns, record);
}

void SessionRecorder::client_status(const ReceivedClientStatus& status) {
  write(client_status_, status.receive_time_ns(), status);
}

void SessionRecorder::view_scene(std::int64_t time_ns, const view::Scene& scene) {
  write(view_scene_, time_ns, scene);
}

void SessionRecorder::view_frame(std::int64_t time_ns, const view::Frame& frame) {
  write(view_frames_, time_ns, frame);
}

void SessionRecorder::flush_if_due() {
  std::lock_guard lock(mutex_);
  if (failed_ || !writer_ || writer_->is_closed()) return;
  try {
    writer_->flush_if_due();
  } catch (const Error& e) {
    failed_ = true;
    spdlog::error("recording stopped (the session goes on): {}", e.what());
  }
}

void SessionRecorder::close() {
  std::lock_guard lock(mutex_);
  if (!writer_ || writer_->is_closed()) return;
  try {
    writer_->close();
  } catch (const Error& e) {
    failed_ = true;
    spdlog::error("recording not closed cleanly: {}", e.what());
  }
}

bool SessionRecorder::failed() const {
  std::lock_guard lock(mutex_);
  return failed_;
}

}  // namespace cohaptic::record
