// ContentHash: a 256-bit BLAKE2b digest (libsodium) of the bytes that define a result,
// used to key on-disk caches and to checksum their payloads.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace cohaptic {

using Digest = std::array<std::uint8_t, 32>;

std::string to_hex(const Digest& digest);

class ContentHasher {
 public:
  ContentHasher();
  ~ContentHasher();
  ContentHasher(const ContentHasher&) = delete;
  ContentHasher& operator=(const ContentHasher&) = delete;

  ContentHasher& bytes(const void* data, std::size_t size);
  ContentHasher& text(std::string_view s) { return value(s.size()).bytes(s.data(), s.size()); }
  template <typename T>
  requires std::is_arithmetic_v<T> ContentHasher& value(T v) { return bytes(&v, sizeof v); }
  template <typename T>
  requires std::is_trivially_copyable_v<T> ContentHasher& values(std::span<const T> v) {
    return value(v.size()).bytes(v.data(), v.size_bytes());
  }
  template <typename Derived>
  ContentHasher& matrix(const Eigen::PlainObjectBase<Derived>& m) {
    value(m.rows()).value(m.cols());
    return bytes(m.data(), static_cast<std::size_t>(m.size()) * sizeof(typename Derived::Scalar));
  }
  Digest finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// Digest of one contiguous buffer.
Digest digest_of(const void* data, std::size_t size);

}  // namespace cohaptic
