// A recording made with another IR format is refused by replay --verify with a message
// naming both versions, never misread: here a server recording whose IR is format 1 (the
// condensed FEM fields at the top level, before the body framework).
#include <gtest/gtest.h>

#include <filesystem>

#include "common/ir/intermediate_representation.h"
#include "common/util/error.h"
#include "lab/replay.h"
#include "proto/record/session_recorder.h"

namespace cohaptic {
namespace {

TEST(RecordingVersions, ReplayRefusesIrsOfAnotherFormatNamingBoth) {
  const std::filesystem::path file =
      std::filesystem::path(::testing::TempDir()) / "format1_server.mcap";
  {
    record::SessionRecorder recorder(file);
    record::SessionConfig config;
    config.set_role("server");
    recorder.config(config);
    wire::IntermediateRepresentation old;
    old.set_format_version(1);
    old.set_epoch(1);
    recorder.ir(10, old);
    recorder.close();
  }
  try {
    verify_recording(file);
    FAIL() << "a format-1 recording was accepted";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("format version 1"), std::string::npos) << message;
    EXPECT_NE(
        message.find(fmt::format("format version {}", IntermediateRepresentation::kFormatVersion)),
        std::string::npos)
        << message;
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
  }
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace cohaptic
