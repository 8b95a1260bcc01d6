#include "common/util/printable.h"

#include <fmt/format.h>

namespace cohaptic {

std::size_t printable_sequence_at(std::string_view text, std::size_t at) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(at);
  if (lead < 0x20 || lead == 0x7f) return 0;
  if (lead < 0x80) return 1;
  const std::size_t length = lead >= 0xf0 ? 4 : lead >= 0xe0 ? 3 : lead >= 0xc2 ? 2 : 0;
  if (length == 0 || lead > 0xf4 || at + length > text.size()) return 0;
  char32_t code = lead & (0x7f >> length);
  for (std::size_t k = 1; k < length; ++k) {
    if ((byte(at + k) & 0xc0) != 0x80) return 0;
    code = (code << 6) | (byte(at + k) & 0x3f);
  }
  const char32_t smallest[] = {0, 0, 0x80, 0x800, 0x10000};
  if (code < smallest[length] || code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff))
    return 0;                                  // overlong, surrogate
  if (code >= 0x80 && code <= 0x9f) return 0;  // C1 controls (U+009B is a terminal's CSI)
  return length;
}

std::string printable(std::string_view text, std::size_t max_bytes) {
  std::string shown;
  for (std::size_t i = 0; i < text.size();) {
    if (shown.size() >= max_bytes) return shown + "...";
    if (const std::size_t length = printable_sequence_at(text, i); length > 0) {
      shown.append(text.substr(i, length));
      i += length;
    } else {
      shown += fmt::format("\\x{:02x}", static_cast<unsigned char>(text[i]));
      ++i;
    }
  }
  return shown;
}

}  // namespace cohaptic
