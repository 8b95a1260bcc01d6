#include "proto/record/recording.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <map>

#include "common/util/error.h"
#include "proto/record/mcap_reader.h"
#include "proto/record/session_recorder.h"
#include "proto/wire/ir_stream.h"

namespace cohaptic::record {
namespace {

template <typename Message>
void add(const McapReader& reader, const McapMessage& message, std::vector<Message>& to,
         std::size_t& unknown) {
  if (auto parsed = reader.parse<Message>(message))
    to.push_back(std::move(*parsed));
  else
    ++unknown;
}

// Opens an IR recorded as a stream block (RecordedIr.compressed_ir) in its stream. A block
// that does not open (a recording cut short mid-stream, say) is dropped and counted unknown.
void open_block(const std::filesystem::path& file,
                std::map<std::uint32_t, wire::IrStreamReader>& streams, Recording& recording) {
  RecordedIr& recorded = recording.irs.back();
  if (!recorded.has_compressed_ir()) return;
  try {
    *recorded.mutable_ir() = streams[recorded.stream()].open(recorded.compressed_ir());
    recorded.clear_compressed_ir();
  } catch (const Error& e) {
    spdlog::warn("{}: an IR of stream {} (block {}) left out: {}", file.string(), recorded.stream(),
                 recorded.compressed_ir().index(), e.what());
    recording.irs.pop_back();
    ++recording.unknown_messages;
  }
}

}  // namespace

Recording read_recording(const std::filesystem::path& file) {
  McapReader reader(file);
  Recording recording;
  recording.file = file;
  std::vector<SessionConfig> configs;
  std::map<std::uint32_t, wire::IrStreamReader> ir_streams;
  while (const auto message = reader.next()) {
    const std::string& topic = reader.channel_of(*message).topic;
    if (topic == topic::kConfig)
      add(reader, *message, configs, recording.unknown_messages);
    else if (topic == topic::kDatagramsIn)
      add(reader, *message, recording.datagrams, recording.unknown_messages);
    else if (topic == topic::kIr) {
      const std::size_t before = recording.irs.size();
      add(reader, *message, recording.irs, recording.unknown_messages);
      if (recording.irs.size() > before) open_block(file, ir_streams, recording);
    } else if (topic == topic::kHaptic)
      add(reader, *message, recording.ticks, recording.unknown_messages);
    else if (topic == topic::kSteps)
      add(reader, *message, recording.steps, recording.unknown_messages);
    else if (topic == topic::kEvents)
      add(reader, *message, recording.events, recording.unknown_messages);
    else if (topic == topic::kClientStatus)
      add(reader, *message, recording.client_statuses, recording.unknown_messages);
    else if (topic == topic::kViewScene)
      add(reader, *message, recording.view_scenes, recording.unknown_messages);
    else if (topic == topic::kViewFrames)
      add(reader, *message, recording.view_frames, recording.unknown_messages);
    else
      ++recording.unknown_messages;
  }
  if (configs.empty() && recording.ticks.empty() && recording.steps.empty())
    throw Error(
        fmt::format("{}: not a cohaptic session recording (no /config, /haptic or /steps messages)",
                    file.string()));
  if (!configs.empty()) {
    recording.config = configs.front();
    recording.has_config = true;
  }
  recording.truncated = reader.truncated();
  recording.truncation = reader.truncation();
  recording.file_bytes = reader.file_size();
  recording.crc = reader.crc_coverage();
  return recording;
}

std::string describe_cut(const Recording& recording) {
  if (!recording.truncated) return "";
  const McapCrcCoverage& crc = recording.crc;
  const std::string cut = fmt::format("cut short at byte {}", recording.file_bytes);
  if (crc.checked_messages == 0) {
    return fmt::format(
        "{}: its {} messages are not covered by any CRC (they are not in chunks with a CRC, as in "
        "a "
        "recording written unchunked): a damaged byte in them goes unnoticed",
        cut, crc.unchecked_messages);
  }
  const double end_s = static_cast<double>(static_cast<std::int64_t>(*crc.checked_end_time_ns) -
                                           recording.config.start_time_ns()) *
                       1e-9;
  std::string line = fmt::format(
      "{}: everything up to t = {:.3f} s is checked by its chunks' CRCs ({} messages, "
      "through byte {})",
      cut, end_s, crc.checked_messages, crc.checked_through_offset);
  if (crc.unchecked_messages > 0)
    line += fmt::format(", except {} messages outside them, not covered by any CRC",
                        crc.unchecked_messages);
  return line;
}

}  // namespace cohaptic::record
