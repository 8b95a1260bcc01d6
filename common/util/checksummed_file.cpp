#include "common/util/checksummed_file.h"

#include <cerrno>
#include <cstring>
#include <fmt/format.h>
#include <fstream>
#include <iterator>

#include "common/util/atomic_file.h"
#include "common/util/content_hash.h"
#include "common/util/error.h"

namespace cohaptic {

ChecksummedRead read_checksummed_file(const std::filesystem::path& file, std::size_t minimum_body) {
  ChecksummedRead result;
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    result.problem = "no cache file";
    return result;
  }
  std::vector<char> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) {
    result.problem = fmt::format("read error: {}", std::strerror(errno));
    return result;
  }
  Digest stored{};
  if (data.size() < minimum_body + stored.size()) {
    result.problem = fmt::format("truncated ({} bytes)", data.size());
    return result;
  }
  const std::size_t body_size = data.size() - stored.size();
  std::memcpy(stored.data(), data.data() + body_size, stored.size());
  if (digest_of(data.data(), body_size) != stored) {
    result.problem = "checksum mismatch (truncated or corrupted)";
    return result;
  }
  data.resize(body_size);
  result.body = std::move(data);
  return result;
}

void write_checksummed_file(const std::filesystem::path& file, std::string_view body) {
  const Digest checksum = digest_of(body.data(), body.size());
  std::error_code ec;
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
  if (ec)
    throw Error(fmt::format("{}: cannot create the cache directory: {}",
                            file.parent_path().string(), ec.message()));
  AtomicFile out(file);
  out.write(body);
  out.write(std::string_view(reinterpret_cast<const char*>(checksum.data()), checksum.size()));
  out.commit();
}

}  // namespace cohaptic
