// Files whose last 32 bytes are the BLAKE2b checksum of everything before them: how the
// on-disk caches detect a truncated or corrupted file and rebuild it.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace cohaptic {

struct ChecksummedRead {
  std::vector<char> body;  ///< the file without its checksum, when `problem` is empty
  std::string
      problem;  ///< "no cache file", "truncated (N bytes)", "checksum mismatch (...)", a read error
};

/// Reads `file` whole and checks its checksum; a body shorter than `minimum_body` bytes
/// counts as truncated. Never throws for a bad or missing file.
ChecksummedRead read_checksummed_file(const std::filesystem::path& file, std::size_t minimum_body);

/// Writes `body` and its checksum atomically (AtomicFile), creating the directory. Throws
/// Error naming the file and the reason; an existing file is left intact then.
void write_checksummed_file(const std::filesystem::path& file, std::string_view body);

}  // namespace cohaptic
