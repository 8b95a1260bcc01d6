// The server's IR encoder (server/ir_encoder.h) and the recording of IR stream blocks
// (proto/record/recording.h):
//   - of a user's IRs that travel whole and are encoded together, only the newest is sent,
//     opening a fresh stream when a superseded one would have; every IR is recorded, and a
//     recording's blocks open to the IRs as built;
//   - compliance rows IRs (each builds on the last) are all sent, in order, also through the
//     encoder's thread;
//   - a recorded block that does not follow its stream's last is left out and counted.
#include <gtest/gtest.h>

#include <mutex>
#include <vector>

#include "proto/record/recording.h"
#include "proto/record/session_recorder.h"
#include "proto/wire/ir_convert.h"
#include "proto/wire/ir_stream.h"
#include "server/ir_encoder.h"
#include "support/scratch_directory.h"

namespace cohaptic {
namespace {

std::shared_ptr<const PreparedIR> ir_of_epoch(int user, std::uint64_t epoch) {
  auto prepared = std::make_shared<PreparedIR>();
  prepared->ir.user = user;
  prepared->ir.epoch = epoch;
  prepared->ir.simulation_time = 0.001 * static_cast<double>(epoch);
  return prepared;
}

BuiltIr whole_in_stream(int user, std::uint64_t epoch, bool fresh) {
  BuiltIr built;
  built.time_ns = static_cast<std::int64_t>(epoch) * 1'000'000;
  built.user = user;
  built.built = ir_of_epoch(user, epoch);
  built.send = built.streamed = true;
  built.fresh = fresh;
  return built;
}

BuiltIr as_rows(int user, std::uint64_t epoch, bool fresh) {
  BuiltIr built = whole_in_stream(user, epoch, fresh);
  built.as_sent = built.built->ir;  // stands for the rows form: sent instead of the IR as built
  return built;
}

TEST(IrEncoder, SendsOnlyTheNewestOfAUsersWholeIrsAndRecordsEveryOne) {
  testing::ScratchDirectory scratch;
  const auto file = scratch.path / "server.mcap";
  LoopStatistics statistics;
  Outbox outbox, later;
  {
    record::SessionRecorder recorder(file);
    recorder.config(record::SessionConfig{});
    IrEncoder encoder(2, &recorder, statistics);
    // User 0's first IR, which starts its stream, is superseded by its second; user 1's stands.
    std::vector<BuiltIr> irs{whole_in_stream(0, 1, true), whole_in_stream(1, 1, true),
                             whole_in_stream(0, 2, false)};
    encoder.encode(irs, outbox);
    // User 0's stream goes on (block 2); then a new start (a new user of the slot, say)
    // superseded by the IR after it, which must begin the new stream in its place.
    std::vector<BuiltIr> more{whole_in_stream(0, 3, false)};
    encoder.encode(more, later);
    std::vector<BuiltIr> restart{whole_in_stream(0, 4, true), whole_in_stream(0, 5, false)};
    encoder.encode(restart, later);
    recorder.close();
  }
  ASSERT_EQ(later.irs.size(), 2u);
  EXPECT_EQ(later.irs[0].message.compressed_ir().index(), 2u);
  EXPECT_EQ(later.irs[1].message.compressed_ir().index(), 1u)
      << "the superseded IR's fresh start passes on";
  {
    wire::IrStreamReader reader;
    EXPECT_EQ(reader.open(later.irs[1].message.compressed_ir()).epoch(), 5u);
  }
  ASSERT_EQ(outbox.irs.size(), 2u);
  EXPECT_EQ(outbox.irs[0].slot, 1);
  EXPECT_EQ(outbox.irs[1].slot, 0);
  for (const auto& sent : outbox.irs)
    EXPECT_TRUE(sent.must_arrive) << "a stream's blocks must all arrive";
  // Each opens a fresh stream: user 0's the one its superseded IR would have opened.
  for (const auto& [slot, epoch] : {std::pair{1, 1u}, std::pair{0, 2u}}) {
    const auto& sent = outbox.irs[slot == 1 ? 0 : 1].message.compressed_ir();
    EXPECT_EQ(sent.index(), 1u) << "slot " << slot;
    wire::IrStreamReader reader;
    EXPECT_EQ(reader.open(sent).epoch(), epoch) << "slot " << slot;
  }
  const LoopSummary summary = statistics.summary();
  EXPECT_EQ(summary.irs_sent, 4u);
  EXPECT_EQ(summary.irs_superseded, 2u);

  const record::Recording recording = record::read_recording(file);
  ASSERT_EQ(recording.irs.size(), 6u) << "every IR built is recorded, the superseded ones too";
  const std::vector<std::pair<int, std::uint64_t>> recorded{{0, 1}, {1, 1}, {0, 2},
                                                            {0, 3}, {0, 4}, {0, 5}};
  for (std::size_t i = 0; i < recorded.size(); ++i) {
    EXPECT_FALSE(recording.irs[i].has_compressed_ir()) << "reading opened the block";
    EXPECT_EQ(recording.irs[i].ir().user(), static_cast<std::uint32_t>(recorded[i].first)) << i;
    EXPECT_EQ(recording.irs[i].ir().epoch(), recorded[i].second) << i;
  }
  EXPECT_EQ(recording.unknown_messages, 0u);
}

TEST(IrEncoder, ItsThreadSendsEveryRowsIrInOrder) {
  LoopStatistics statistics;
  std::mutex mutex;
  std::vector<Outbox> handed_over;
  IrEncoder encoder(1, nullptr, statistics);
  encoder.start([&](Outbox&& outbox) {
    std::lock_guard lock(mutex);
    handed_over.push_back(std::move(outbox));
  });
  constexpr std::uint64_t kIrs = 40;
  for (std::uint64_t epoch = 1; epoch <= kIrs; ++epoch)
    encoder.post({as_rows(0, epoch, epoch == 1)});
  encoder.stop();
  wire::IrStreamReader reader;
  std::uint64_t expected = 1;
  for (const Outbox& outbox : handed_over)
    for (const auto& sent : outbox.irs)
      EXPECT_EQ(reader.open(sent.message.compressed_ir()).epoch(), expected++);
  EXPECT_EQ(expected, kIrs + 1) << "rows build on each other: none is superseded";
  EXPECT_EQ(statistics.summary().irs_superseded, 0u);
}

TEST(Recording, LeavesOutABlockThatDoesNotFollowItsStream) {
  testing::ScratchDirectory scratch;
  const auto file = scratch.path / "client.mcap";
  {
    record::SessionRecorder recorder(file);
    recorder.config(record::SessionConfig{});
    wire::IrStreamWriter writer;
    std::vector<wire::CompressedIr> blocks;
    for (std::uint64_t epoch = 1; epoch <= 3; ++epoch)
      blocks.push_back(writer.compress(wire::to_wire(ir_of_epoch(0, epoch)->ir), epoch == 1));
    recorder.ir_block(1, 0, blocks[0]);
    recorder.ir_block(3, 0, blocks[2]);  // block 2 missing
    recorder.close();
  }
  const record::Recording recording = record::read_recording(file);
  ASSERT_EQ(recording.irs.size(), 1u);
  EXPECT_EQ(recording.irs[0].ir().epoch(), 1u);
  EXPECT_EQ(recording.unknown_messages, 1u);
}

}  // namespace
}  // namespace cohaptic
