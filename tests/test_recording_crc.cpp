// A recording cut short (its writer killed, the disk full) is checked by the CRCs of its
// chunks. Client recordings made with SessionRecorder, cut inside their last chunk:
//   - intact, it reads its complete chunks, and read_recording, describe_cut and
//     `cohaptic-lab replay --verify` / `--summary` say up to which time the CRCs vouch for it;
//   - with one byte flipped in its last complete chunk (a tick's fade, 1.0 -> 1.0000001,
//     which the re-run of the ticks would not notice), read_recording, verify_recording and
//     `cohaptic-lab replay --verify` fail, naming the file, the chunk and its time range;
//   - the same recording without chunks (as written unchunked), cut and flipped the same
//     way, reads with the damage unnoticed, and replay says that no CRC covers it.
#include <gtest/gtest.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "common/util/error.h"
#include "lab/replay.h"
#include "proto/record/recording.h"
#include "proto/record/session_recorder.h"
#include "support/mcap_layout.h"
#include "support/process.h"
#include "support/run_program.h"

namespace cohaptic {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using Bytes = testing::Bytes;
using testing::RawRecord;

constexpr std::int64_t kStartNs = 5'000'000'000;
constexpr int kBatches = 4;
constexpr int kTicksPerBatch = 200;

// A client's recording: its configuration, then kBatches x kTicksPerBatch haptic ticks at
// 1 kHz without a tool (their re-run is trivial: no force), each batch after the recorder's
// flush interval, so that the ticks span several chunks.
void record_ticks(const fs::path& file) {
  record::SessionRecorder recorder(file);
  record::SessionConfig config;
  config.set_role("client");
  config.set_user("crc");
  config.set_start_time_ns(kStartNs);
  config.set_force_limit(3.3);
  recorder.config(config);
  for (int batch = 0; batch < kBatches; ++batch) {
    std::this_thread::sleep_for(120ms);  // stimulus: the flush interval passing
    for (int i = 0; i < kTicksPerBatch; ++i) {
      record::HapticTick tick;
      tick.set_time_ns(kStartNs + std::int64_t{batch * kTicksPerBatch + i} * 1'000'000);
      tick.set_fade(1.0f);
      recorder.tick(tick);
    }
  }
  recorder.close();
}

// A recording cut in the middle of its last chunk: the chunk before it is its last complete one.
struct CutRecording {
  Bytes bytes;  ///< the prefix left
  RawRecord last_complete{};
  testing::RawChunk last_complete_fields{};
  std::size_t messages = 0;  ///< in its complete chunks
};

CutRecording cut_in_last_chunk(const Bytes& whole) {
  std::vector<RawRecord> chunks;
  for (const RawRecord& r : testing::walk(whole))
    if (r.opcode == 0x06) chunks.push_back(r);
  EXPECT_GE(chunks.size(), 4u) << "schemas and channels, the configuration, ticks, ticks";
  CutRecording cut;
  const RawRecord& last = chunks.back();
  cut.bytes.assign(whole.begin(),
                   whole.begin() + static_cast<long>(last.offset + 9 + last.length / 2));
  cut.last_complete = chunks[chunks.size() - 2];
  cut.last_complete_fields = testing::read_chunk(whole, cut.last_complete);
  cut.messages = testing::messages_of(cut.bytes).size();
  return cut;
}

// Flips the lowest bit of the fade (1.0f: 00 00 80 3F after the tag of field 8, fixed32) of
// the last tick in bytes[begin, end).
void flip_last_fade(Bytes& bytes, std::size_t begin, std::size_t end) {
  const Bytes fade = {0x45, 0x00, 0x00, 0x80, 0x3F};
  const auto from = bytes.begin() + static_cast<long>(begin),
             to = bytes.begin() + static_cast<long>(end);
  const auto at = std::find_end(from, to, fade.begin(), fade.end());
  ASSERT_NE(at, to) << "no tick's fade in the range";
  at[1] ^= 0x01;
}

std::string lab_replay(const fs::path& file, const std::string& mode, int& exit_code) {
  const testing::ProgramRun run =
      testing::run_program(COHAPTIC_LAB_EXE, "replay '" + file.string() + "' " + mode, true);
  exit_code = run.exit_code;
  return run.out;
}

TEST(RecordingCrc, ACutRecordingReadsItsCompleteChunksAndSaysHowFarTheirCrcsVouch) {
  const fs::path dir = testing::scratch_directory("recording-crc-cut");
  record_ticks(dir / "whole.mcap");
  const CutRecording cut = cut_in_last_chunk(testing::read_bytes(dir / "whole.mcap"));
  const fs::path file = dir / "cut.mcap";
  testing::write_bytes(file, cut.bytes);

  const record::Recording rec = record::read_recording(file);
  EXPECT_TRUE(rec.truncated);
  EXPECT_TRUE(rec.has_config);
  ASSERT_EQ(rec.ticks.size(), cut.messages - 1) << "every tick of the complete chunks";
  EXPECT_LT(rec.ticks.size(), std::size_t{kBatches * kTicksPerBatch});
  EXPECT_EQ(rec.file_bytes, cut.bytes.size());
  EXPECT_EQ(rec.crc.checked_messages, cut.messages);
  EXPECT_EQ(rec.crc.unchecked_messages, 0u);
  EXPECT_EQ(rec.crc.checked_through_offset, cut.last_complete.end());
  EXPECT_EQ(rec.crc.checked_end_time_ns, cut.last_complete_fields.message_end_time);
  EXPECT_EQ(static_cast<std::int64_t>(cut.last_complete_fields.message_end_time),
            rec.ticks.back().time_ns());

  const std::string line = fmt::format(
      "cut short at byte {}: everything up to t = {:.3f} s is checked by its chunks' CRCs ({} "
      "messages, through byte {})",
      cut.bytes.size(), static_cast<double>(rec.ticks.back().time_ns() - kStartNs) * 1e-9,
      cut.messages, cut.last_complete.end());
  EXPECT_EQ(record::describe_cut(rec), line);

  const VerifyResult result = verify_recording(file);
  EXPECT_TRUE(result.ok) << result.first_difference;
  EXPECT_EQ(result.checked, 2 * rec.ticks.size());
  int exit_code = -1;
  const std::string verify = lab_replay(file, "--verify", exit_code);
  EXPECT_EQ(exit_code, 0) << verify;
  EXPECT_NE(verify.find("verify: " + line + "\n"), std::string::npos) << verify;
  EXPECT_NE(verify.find("verify: identical"), std::string::npos) << verify;
  const std::string summary = lab_replay(file, "--summary", exit_code);
  EXPECT_EQ(exit_code, 0) << summary;
  EXPECT_NE(summary.find("integrity   " + line + "\n"), std::string::npos) << summary;

  // The whole recording is complete: nothing to say.
  const record::Recording whole = record::read_recording(dir / "whole.mcap");
  EXPECT_FALSE(whole.truncated);
  EXPECT_EQ(record::describe_cut(whole), "");
  EXPECT_EQ(whole.crc.checked_messages, std::uint64_t{kBatches * kTicksPerBatch + 1});
}

TEST(RecordingCrc, AByteFlippedInTheLastCompleteChunkOfACutRecordingIsFoundAndNamed) {
  const fs::path dir = testing::scratch_directory("recording-crc-flipped");
  record_ticks(dir / "whole.mcap");
  CutRecording cut = cut_in_last_chunk(testing::read_bytes(dir / "whole.mcap"));
  flip_last_fade(cut.bytes, cut.last_complete_fields.records_begin,
                 cut.last_complete_fields.records_end);
  const fs::path file = dir / "flipped.mcap";
  testing::write_bytes(file, cut.bytes);

  const std::vector<std::string> parts = {
      file.string(), fmt::format("Chunk record at offset {}", cut.last_complete.offset),
      fmt::format("messages logged from {} to {} ns", cut.last_complete_fields.message_start_time,
                  cut.last_complete_fields.message_end_time),
      "the chunk is corrupt"};
  const auto expect_named = [&](const std::string& what) {
    for (const std::string& part : parts) EXPECT_NE(what.find(part), std::string::npos) << what;
  };
  try {
    record::read_recording(file);
    ADD_FAILURE() << "a damaged chunk was read";
  } catch (const Error& e) {
    expect_named(e.what());
  }
  try {
    verify_recording(file);
    ADD_FAILURE() << "a damaged chunk was verified";
  } catch (const Error& e) {
    expect_named(e.what());
  }
  int exit_code = -1;
  const std::string verify = lab_replay(file, "--verify", exit_code);
  EXPECT_EQ(exit_code, 1) << verify;
  expect_named(verify);
  EXPECT_EQ(verify.find("verify: identical"), std::string::npos) << verify;
}

TEST(RecordingCrc, AnUnchunkedRecordingCutShortSaysNoCrcCoversIt) {
  const fs::path dir = testing::scratch_directory("recording-crc-unchunked");
  record_ticks(dir / "whole.mcap");
  const Bytes unchunked = testing::unchunked(testing::read_bytes(dir / "whole.mcap"));
  const std::vector<testing::RawMessage> messages = testing::messages_of(unchunked);
  ASSERT_EQ(messages.size(), std::size_t{kBatches * kTicksPerBatch + 1});
  // Cut inside its 600th message, with the fade of the tick before flipped as above.
  Bytes cut(unchunked.begin(),
            unchunked.begin() + static_cast<long>(messages[600].record.offset + 20));
  flip_last_fade(cut, messages[599].record.offset, messages[599].record.end());
  const fs::path file = dir / "cut.mcap";
  testing::write_bytes(file, cut);

  const record::Recording rec = record::read_recording(file);  // the damage goes unnoticed
  EXPECT_TRUE(rec.truncated);
  ASSERT_EQ(rec.ticks.size(), 599u);
  EXPECT_NE(rec.ticks.back().fade(), 1.0f) << "the flipped byte came through";
  EXPECT_EQ(rec.crc.checked_messages, 0u);
  EXPECT_EQ(rec.crc.unchecked_messages, 600u);
  const std::string line = fmt::format(
      "cut short at byte {}: its 600 messages are not covered by any CRC (they are not in chunks "
      "with a CRC, as in a "
      "recording written unchunked): a damaged byte in them goes unnoticed",
      cut.size());
  EXPECT_EQ(record::describe_cut(rec), line);
  int exit_code = -1;
  const std::string verify = lab_replay(file, "--verify", exit_code);
  EXPECT_EQ(exit_code, 0) << verify;
  EXPECT_NE(verify.find("verify: " + line + "\n"), std::string::npos) << verify;
  const std::string summary = lab_replay(file, "--summary", exit_code);
  EXPECT_NE(summary.find("integrity   " + line + "\n"), std::string::npos) << summary;
}

}  // namespace
}  // namespace cohaptic
