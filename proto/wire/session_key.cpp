#include "proto/wire/session_key.h"

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <string_view>

#include "common/util/error.h"
#include "proto/wire/sodium_ready.h"

namespace cohaptic::wire {
namespace {

constexpr std::size_t kHexChars = 2 * sizeof(SessionKey::bytes);
constexpr std::size_t kMaxKeyFileBytes = 4096;  // a key file is ~65 bytes; refuse to slurp anything big

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw cohaptic::Error(fmt::format("{}: {}", file.string(), what));
}

}  // namespace

SessionKey load_session_key(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file, fmt::format("cannot open key file: {}", std::strerror(errno)));
  std::string text(kMaxKeyFileBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) fail(file, "cannot read key file");
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > kMaxKeyFileBytes)
    fail(file, fmt::format("expected 64 hexadecimal characters, the file is larger than {} bytes", kMaxKeyFileBytes));

  SessionKey key;
  std::size_t digits = 0;
  long line = 1, column = 0;
  for (const char c : text) {
    ++column;
    if (c == '\n') {
      ++line;
      column = 0;
    }
    if (is_space(c)) continue;
    const int value = hex_value(c);
    if (value < 0) {
      sodium_memzero(key.bytes.data(), key.bytes.size());
      sodium_memzero(text.data(), text.size());
      const auto byte = static_cast<unsigned char>(c);
      fail(file, byte >= 0x20 && byte < 0x7f
                     ? fmt::format("expected 64 hexadecimal characters, found '{}' at line {} column {}", c, line, column)
                     : fmt::format("expected 64 hexadecimal characters, found byte 0x{:02x} at line {} column {}",
                                   static_cast<unsigned>(byte), line, column));
    }
    if (digits < kHexChars) {
      std::uint8_t& b = key.bytes[digits / 2];
      b = static_cast<std::uint8_t>(digits % 2 == 0 ? value << 4 : b | value);
    }
    ++digits;
  }
  sodium_memzero(text.data(), text.size());
  if (digits != kHexChars) {
    sodium_memzero(key.bytes.data(), key.bytes.size());
    fail(file, fmt::format("expected 64 hexadecimal characters, found {}", digits));
  }
  if (sodium_is_zero(key.bytes.data(), key.bytes.size())) fail(file, "the key is all zeros");
  return key;
}

SessionKey development_key() {
  static constexpr std::string_view kText = "cohaptic-development-key-public!";
  static_assert(kText.size() == sizeof(SessionKey::bytes));
  SessionKey key;
  for (std::size_t i = 0; i < kText.size(); ++i) key.bytes[i] = static_cast<std::uint8_t>(kText[i]);
  return key;
}

std::string to_hex(const SessionKey& key) {
  std::string hex(kHexChars + 1, '\0');
  sodium_bin2hex(hex.data(), hex.size(), key.bytes.data(), key.bytes.size());
  hex.resize(kHexChars);
  return hex;
}

void write_session_key(const std::filesystem::path& file) {
  ensure_sodium();
  SessionKey key;
  randombytes_buf(key.bytes.data(), key.bytes.size());
  std::string text = to_hex(key) + "\n";
  sodium_memzero(key.bytes.data(), key.bytes.size());

  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, S_IRUSR | S_IWUSR);
  if (fd < 0) {
    const int error = errno;
    sodium_memzero(text.data(), text.size());
    fail(file, fmt::format("cannot create key file: {}", std::strerror(error)));
  }
  std::string problem;
  if (::fchmod(fd, S_IRUSR | S_IWUSR) != 0) problem = fmt::format("cannot set mode 0600: {}", std::strerror(errno));
  std::size_t written = 0;
  while (problem.empty() && written < text.size()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) problem = fmt::format("cannot write key file: {}", std::strerror(errno));
    else written += static_cast<std::size_t>(n);
  }
  if (problem.empty() && ::fsync(fd) != 0) problem = fmt::format("cannot sync key file: {}", std::strerror(errno));
  if (::close(fd) != 0 && problem.empty()) problem = fmt::format("cannot close key file: {}", std::strerror(errno));
  sodium_memzero(text.data(), text.size());
  if (!problem.empty()) {
    ::unlink(file.c_str());
    fail(file, problem);
  }
}

}  // namespace cohaptic::wire
