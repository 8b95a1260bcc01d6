// The IR stream (proto/wire/ir_stream.h): every IR comes out of it bit for bit, what repeats
// from IR to IR costs little, a fresh start resets both sides, and a reader refuses blocks
// out of turn, garbage and decompression bombs with a reason, until the next fresh start.
#include <gtest/gtest.h>
#include <zstd.h>

#include <fstream>
#include <string>
#include <vector>

#include "common/util/error.h"
#include "proto/wire/ir_stream.h"

namespace cohaptic {
namespace {

// The IR fuzzer's seeds: real IRs of every body kind, recorded by tests/fuzz/make_seeds.sh.
std::vector<wire::IntermediateRepresentation> seed_irs() {
  std::vector<wire::IntermediateRepresentation> irs;
  for (const char* name : {"smallest", "sphere", "with_remote", "rows_first", "mass_spring",
                           "home_spring", "separation"}) {
    std::ifstream in(std::string(COHAPTIC_SOURCE_DIR) + "/tests/fuzz/corpus/ir/" + name,
                     std::ios::binary);
    wire::IntermediateRepresentation ir;
    EXPECT_TRUE(ir.ParseFromIstream(&in)) << name;
    irs.push_back(std::move(ir));
  }
  return irs;
}

TEST(IrStream, EveryIrComesOutBitForBitAndWhatRepeatsCostsLittle) {
  const std::vector<wire::IntermediateRepresentation> irs = seed_irs();
  wire::IrStreamWriter writer;
  wire::IrStreamReader reader;
  std::size_t plain_first = 0, packed_first = 0, plain_again = 0, packed_again = 0;
  for (int pass = 0; pass < 2; ++pass)
    for (std::size_t i = 0; i < irs.size(); ++i) {
      const wire::CompressedIr block = writer.compress(irs[i], pass == 0 && i == 0);
      EXPECT_EQ(block.index(), static_cast<std::uint64_t>(pass * irs.size() + i + 1));
      EXPECT_EQ(reader.open(block).SerializeAsString(), irs[i].SerializeAsString())
          << "pass " << pass << ", IR " << i;
      (pass == 0 ? plain_first : plain_again) += irs[i].ByteSizeLong();
      (pass == 0 ? packed_first : packed_again) += block.zstd().size();
    }
  std::printf("  %zu IRs: %zu -> %zu bytes the first time, %zu -> %zu again\n", irs.size(),
              plain_first, packed_first, plain_again, packed_again);
  // The second time, every IR repeats one already in the window: a few bytes each.
  EXPECT_LT(packed_again, plain_again / 20);
  EXPECT_LT(packed_first, plain_first);
}

TEST(IrStream, AFreshStartResetsBothSides) {
  const std::vector<wire::IntermediateRepresentation> irs = seed_irs();
  wire::IrStreamWriter writer;
  wire::IrStreamReader first;
  first.open(writer.compress(irs[0], true));
  first.open(writer.compress(irs[1], false));
  const wire::CompressedIr fresh = writer.compress(irs[1], true);
  EXPECT_EQ(fresh.index(), 1u);
  wire::IrStreamReader newcomer;  // never saw the blocks before
  EXPECT_EQ(newcomer.open(fresh).SerializeAsString(), irs[1].SerializeAsString());
  EXPECT_EQ(first.open(fresh).SerializeAsString(), irs[1].SerializeAsString());
}

TEST(IrStream, RefusesBlocksOutOfTurnGarbageAndBombsUntilAFreshStart) {
  const std::vector<wire::IntermediateRepresentation> irs = seed_irs();
  wire::IrStreamWriter writer;
  wire::IrStreamReader reader;
  reader.open(writer.compress(irs[0], true));
  writer.compress(irs[1], false);  // lost on the way
  const wire::CompressedIr third = writer.compress(irs[2], false);
  try {
    reader.open(third);
    ADD_FAILURE() << "a block out of turn was opened";
  } catch (const Error& e) {
    EXPECT_NE(
        std::string(e.what()).find("block 3 of its stream, and this client opened block 1 last"),
        std::string::npos)
        << e.what();
  }
  EXPECT_THROW(reader.open(writer.compress(irs[3], false)),
               Error);  // nothing but a fresh start now
  EXPECT_EQ(reader.open(writer.compress(irs[3], true)).SerializeAsString(),
            irs[3].SerializeAsString());

  wire::CompressedIr garbage;
  garbage.set_index(1);
  garbage.set_zstd(std::string(200, '\x5a'));
  EXPECT_THROW(reader.open(garbage), Error);

  // 65 MiB of zeros in a few kB: refused once the limit is reached.
  ZSTD_CCtx* cctx = ZSTD_createCCtx();
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_windowLog, wire::kIrStreamWindowLog);
  const std::string zeros(std::size_t{65} << 20, '\0');
  std::string bomb(std::size_t{1} << 20, '\0');
  const std::size_t size =
      ZSTD_compress2(cctx, bomb.data(), bomb.size(), zeros.data(), zeros.size());
  ZSTD_freeCCtx(cctx);
  ASSERT_FALSE(ZSTD_isError(size));
  bomb.resize(size);
  wire::CompressedIr block;
  block.set_index(1);
  block.set_zstd(bomb);
  try {
    reader.open(block);
    ADD_FAILURE() << "a bomb was opened";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("decompresses to more than"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace cohaptic
