// CRC-32 as MCAP uses it (the IEEE 802.3 / zlib CRC: reflected polynomial 0xEDB88320,
// initial value and final XOR 0xFFFFFFFF), computed incrementally over any number of
// byte ranges. MCAP stores it in DataEnd (the data section) and the Footer (the summary);
// the value 0 there means "not computed".
//
// Invariant: Crc32{}.value() is the CRC of the empty input (0); update(a) then update(b)
// gives the same value as update(a + b).
#pragma once

#include <cstdint>
#include <span>

namespace cohaptic::record {

class Crc32 {
 public:
  void update(std::span<const std::uint8_t> bytes);
  /// The CRC of every byte passed to update() so far.
  std::uint32_t value() const { return state_ ^ 0xFFFFFFFFu; }

 private:
  std::uint32_t state_ = 0xFFFFFFFFu;
};

/// The CRC-32 of one byte range.
std::uint32_t crc32(std::span<const std::uint8_t> bytes);

}  // namespace cohaptic::record
