#include "common/util/line_reader.h"

#include <fmt/format.h>

#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <system_error>
#include <utility>

#include "common/util/error.h"

namespace cohaptic {

std::ifstream open_text_file(const std::filesystem::path& path) {
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  const int error_number = errno;
  if (!in)
    throw Error(fmt::format(
        "cannot open {}: {}", path.string(),
        error_number != 0 ? std::generic_category().message(error_number) : "unknown error"));
  std::error_code ignored;
  if (std::filesystem::is_directory(path, ignored))
    throw Error(
        fmt::format("cannot open {}: {}", path.string(), std::generic_category().message(EISDIR)));
  return in;
}

LineReader::LineReader(std::istream& in, std::string source_name)
    : in_(in), source_name_(std::move(source_name)) {}

bool LineReader::next() {
  tokens_.clear();
  if (!std::getline(in_, line_)) {
    line_.clear();
    if (in_.bad())
      throw Error(fmt::format("{}: read error after line {}", source_name_, line_number_));
    return false;
  }
  ++line_number_;
  if (!line_.empty() && line_.back() == '\r') line_.pop_back();
  const std::string_view text(line_);
  std::size_t pos = 0;
  while (pos < text.size()) {
    const auto is_blank = [](char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; };
    while (pos < text.size() && is_blank(text[pos])) ++pos;
    const std::size_t start = pos;
    while (pos < text.size() && !is_blank(text[pos])) ++pos;
    if (pos > start) tokens_.push_back(text.substr(start, pos - start));
  }
  return true;
}

bool LineReader::next_nonblank() {
  while (next())
    if (!tokens_.empty()) return true;
  return false;
}

void LineReader::fail(const std::string& what) const { fail_at(line_number_, what); }

void LineReader::fail_at(long line, const std::string& what) const {
  throw ParseError(source_name_, line > 0 ? line : 1, what);
}

namespace {

std::string_view without_plus(std::string_view token) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-' && token[1] != '+')
    token.remove_prefix(1);
  return token;
}

}  // namespace

std::int64_t LineReader::integer(std::string_view token, std::string_view field) const {
  const std::string_view digits = without_plus(token);
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec == std::errc::result_out_of_range)
    fail(fmt::format("{} {} is out of range", field, quoted(token)));
  if (ec != std::errc() || end != digits.data() + digits.size())
    fail(fmt::format("expected {}, found {}", field, quoted(token)));
  return value;
}

double LineReader::real(std::string_view token, std::string_view field) const {
  const std::string_view digits = without_plus(token);
  double value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (end != digits.data() + digits.size() ||
      (ec != std::errc() && ec != std::errc::result_out_of_range))
    fail(fmt::format("expected {}, found {}", field, quoted(token)));
  if (ec == std::errc::result_out_of_range) {
    // Overflow is an error; underflow (|x| < 1e-308) is a legitimate tiny or zero value.
    value = std::strtod(std::string(digits).c_str(), nullptr);
  }
  if (!std::isfinite(value)) fail(fmt::format("non-finite {} {}", field, quoted(token)));
  return value;
}

std::string LineReader::quoted(std::string_view text) {
  constexpr std::size_t kMax = 40;
  std::string out = "'";
  for (std::size_t i = 0; i < text.size() && i < kMax; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f)
      out += static_cast<char>(c);
    else
      out += fmt::format("\\x{:02x}", c);
  }
  out += text.size() > kMax ? "'..." : "'";
  return out;
}

}  // namespace cohaptic
