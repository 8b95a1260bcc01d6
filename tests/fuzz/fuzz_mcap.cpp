// Fuzz target: the MCAP reader (proto/record/mcap_reader.h) and the session recording
// built on it (proto/record/recording.h), as replay and summarize read recordings.
//
// Input: the bytes of a file. Properties:
//   - McapReader and read_recording() either read the file or throw cohaptic::Error;
//   - what the reader reports is consistent: a complete file is not truncated, every
//     message's channel was declared, the readable prefix is no longer than the file;
//   - a crashed writer's file reads as far as it got: when the whole file reads without
//     error, its first half (and all of it but the last byte) reads without error too, as
//     truncated or complete, yielding the first messages of the whole, in order.
#include <cstdint>
#include <span>
#include <vector>

#include "common/util/error.h"
#include "proto/record/mcap_reader.h"
#include "proto/record/recording.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using namespace cohaptic;
using fuzz::require;

struct Read {
  std::vector<record::McapMessage> messages;
  bool failed = false;
};

Read read_all(std::span<const std::uint8_t> bytes, const char* extension) {
  Read read;
  try {
    record::McapReader reader(fuzz::scratch_file(bytes, extension));
    while (const auto message = reader.next()) {
      require(reader.channels().count(message->channel_id) == 1,
              "a message's channel was declared");
      reader.schema_of(*message);
      read.messages.push_back(*message);
    }
    require(!(reader.complete() && reader.truncated()),
            "a file is complete or truncated, not both");
    require(reader.valid_bytes() <= bytes.size(), "the readable prefix lies within the file");
  } catch (const Error&) {
    read.failed = true;
  }
  return read;
}

void require_prefix_reads(std::span<const std::uint8_t> bytes, std::size_t length,
                          const Read& whole) {
  const Read prefix = read_all(bytes.first(length), ".part.mcap");
  require(!prefix.failed, "a prefix of a readable file reads");
  require(prefix.messages.size() <= whole.messages.size(),
          "a prefix yields no more messages than the whole");
  for (std::size_t i = 0; i < prefix.messages.size(); ++i)
    require(prefix.messages[i] == whole.messages[i],
            "a prefix yields the first messages of the whole");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  const Read whole = read_all(bytes, ".mcap");
  if (!whole.failed && size > 0) {
    require_prefix_reads(bytes, size / 2, whole);
    require_prefix_reads(bytes, size - 1, whole);
  }
  try {
    record::read_recording(fuzz::scratch_file(bytes, ".mcap"));
  } catch (const Error&) {
  }
  return 0;
}
