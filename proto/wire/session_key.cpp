#include "proto/wire/session_key.h"

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <string_view>

#include "common/util/error.h"
#include "proto/wire/sodium_ready.h"
#include "proto/wire/traffic_keys.h"

namespace cohaptic::wire {
namespace {

constexpr std::size_t kHexChars = 2 * sizeof(SecretBytes::bytes);
constexpr std::size_t kMaxKeyFileBytes =
    4096;  // a key file is ~80 bytes; refuse to slurp anything big
constexpr std::string_view kParticipantWord = "participant";

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

/// Wipes a string holding key material when it goes out of scope, however that happens.
struct WipedText {
  std::string text;
  ~WipedText() { sodium_memzero(text.data(), text.size()); }
};

/// The file's bytes, once it is known to be a regular file that only its owner may use.
/// The mode is checked on the descriptor that is read, so the file cannot be swapped between.
void read_private_file(const std::filesystem::path& file, std::string& text) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail(file, fmt::format("cannot open key file: {}", std::strerror(errno)));
  struct stat status {};
  std::string problem;
  if (::fstat(fd, &status) != 0)
    problem = fmt::format("cannot stat key file: {}", std::strerror(errno));
  else if (!S_ISREG(status.st_mode))
    problem = "a key file must be a regular file";
  else if ((status.st_mode & 077) != 0)
    problem = fmt::format(
        "the key file has mode {:04o}: its group or others may use it, so it is no secret; "
        "run `chmod 600 {}`",
        status.st_mode & 07777, file.string());
  text.assign(kMaxKeyFileBytes + 1, '\0');
  std::size_t size = 0;
  while (problem.empty() && size < text.size()) {
    const ssize_t n = ::read(fd, text.data() + size, text.size() - size);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) problem = fmt::format("cannot read key file: {}", std::strerror(errno));
    if (n <= 0) break;
    size += static_cast<std::size_t>(n);
  }
  ::close(fd);
  text.resize(size);
  if (!problem.empty()) fail(file, problem);
  if (size > kMaxKeyFileBytes)
    fail(file,
         fmt::format("expected a key file, the file is larger than {} bytes", kMaxKeyFileBytes));
}

/// 64 hex digits from `text` (whitespace ignored) into `out`; `line` is the line `text` starts on.
void parse_hex_key(const std::filesystem::path& file, std::string_view text, long line,
                   SecretBytes& out) {
  std::size_t digits = 0;
  long column = 0;
  for (const char c : text) {
    ++column;
    if (c == '\n') {
      ++line;
      column = 0;
    }
    if (is_space(c)) continue;
    const int value = hex_value(c);
    if (value < 0) {
      const auto byte = static_cast<unsigned char>(c);
      fail(file,
           byte >= 0x20 && byte < 0x7f
               ? fmt::format("expected 64 hexadecimal characters, found '{}' at line {} column {}",
                             c, line, column)
               : fmt::format(
                     "expected 64 hexadecimal characters, found byte 0x{:02x} at line {} column {}",
                     static_cast<unsigned>(byte), line, column));
    }
    if (digits < kHexChars) {
      std::uint8_t& b = out.bytes[digits / 2];
      b = static_cast<std::uint8_t>(digits % 2 == 0 ? value << 4 : b | value);
    }
    ++digits;
  }
  if (digits != kHexChars)
    fail(file, fmt::format("expected 64 hexadecimal characters, found {}", digits));
  if (sodium_is_zero(out.bytes.data(), out.bytes.size())) fail(file, "the key is all zeros");
}

/// "participant K" on the first line: K.
std::uint32_t parse_participant_line(const std::filesystem::path& file, std::string_view line) {
  std::string_view rest = line.substr(kParticipantWord.size());
  while (!rest.empty() && is_space(rest.front())) rest.remove_prefix(1);
  while (!rest.empty() && is_space(rest.back())) rest.remove_suffix(1);
  std::uint32_t slot = 0;
  const auto [end, error] = std::from_chars(rest.data(), rest.data() + rest.size(), slot);
  if (rest.empty() || error != std::errc() || end != rest.data() + rest.size() ||
      slot >= kJoiningSender - 1)
    fail(file,
         fmt::format("line 1: expected `participant K` with K a slot number, found `{}`", line));
  return slot;
}

/// Creates `file` exclusively with mode 0600 and writes `text` to it; on failure removes it and
/// throws.
void write_private_file(const std::filesystem::path& file, const std::string& text) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, S_IRUSR | S_IWUSR);
  if (fd < 0) fail(file, fmt::format("cannot create key file: {}", std::strerror(errno)));
  std::string problem;
  if (::fchmod(fd, S_IRUSR | S_IWUSR) != 0)
    problem = fmt::format("cannot set mode 0600: {}", std::strerror(errno));
  std::size_t written = 0;
  while (problem.empty() && written < text.size()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      problem = fmt::format("cannot write key file: {}", std::strerror(errno));
    else
      written += static_cast<std::size_t>(n);
  }
  if (problem.empty() && ::fsync(fd) != 0)
    problem = fmt::format("cannot sync key file: {}", std::strerror(errno));
  if (::close(fd) != 0 && problem.empty())
    problem = fmt::format("cannot close key file: {}", std::strerror(errno));
  if (!problem.empty()) {
    ::unlink(file.c_str());
    fail(file, problem);
  }
}

}  // namespace

SecretBytes::~SecretBytes() { sodium_memzero(bytes.data(), bytes.size()); }

std::variant<SessionKey, ParticipantKey> load_key_file(const std::filesystem::path& file) {
  WipedText contents;
  read_private_file(file, contents.text);
  std::string_view text = contents.text;
  std::size_t start = 0;
  while (start < text.size() && is_space(text[start])) ++start;
  if (text.substr(start).starts_with(kParticipantWord)) {
    const std::size_t end_of_line = std::min(text.find('\n', start), text.size());
    ParticipantKey participant;
    participant.slot = parse_participant_line(file, text.substr(start, end_of_line - start));
    const long lines_before = static_cast<long>(
        std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(end_of_line), '\n'));
    parse_hex_key(file, text.substr(end_of_line), 1 + lines_before, participant.key);
    return participant;
  }
  SessionKey key;
  parse_hex_key(file, text, 1, key);
  return key;
}

SessionKey load_session_key(const std::filesystem::path& file) {
  auto loaded = load_key_file(file);
  if (const auto* participant = std::get_if<ParticipantKey>(&loaded))
    fail(file,
         fmt::format("this is participant {}'s key file; the server needs the session key file",
                     participant->slot));
  return std::get<SessionKey>(loaded);
}

SessionKey development_key() {
  static constexpr std::string_view kText = "cohaptic-development-key-public!";
  static_assert(kText.size() == sizeof(SessionKey::bytes));
  SessionKey key;
  for (std::size_t i = 0; i < kText.size(); ++i) key.bytes[i] = static_cast<std::uint8_t>(kText[i]);
  return key;
}

std::string to_hex(const SecretBytes& key) {
  std::string hex(kHexChars + 1, '\0');
  sodium_bin2hex(hex.data(), hex.size(), key.bytes.data(), key.bytes.size());
  hex.resize(kHexChars);
  return hex;
}

void write_session_key(const std::filesystem::path& file) {
  ensure_sodium();
  SessionKey key;
  randombytes_buf(key.bytes.data(), key.bytes.size());
  const WipedText text{to_hex(key) + "\n"};
  write_private_file(file, text.text);
}

void write_participant_key(const std::filesystem::path& file, const SessionKey& session,
                           std::uint32_t slot) {
  const TrafficKey key = participant_key(session, slot);
  const WipedText text{fmt::format("{} {}\n{}\n", kParticipantWord, slot, to_hex(key))};
  write_private_file(file, text.text);
}

}  // namespace cohaptic::wire
