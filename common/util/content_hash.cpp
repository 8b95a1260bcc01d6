#include "common/util/content_hash.h"

#include <sodium.h>

#include "common/util/error.h"

namespace cohaptic {

struct ContentHasher::State {
  crypto_generichash_state state;
};

std::string to_hex(const Digest& digest) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(2 * digest.size());
  for (std::uint8_t b : digest) {
    out.push_back(kHex[b >> 4]);
    out.push_back(kHex[b & 15]);
  }
  return out;
}

ContentHasher::ContentHasher() : state_(std::make_unique<State>()) {
  if (sodium_init() < 0) throw Error("libsodium failed to initialise");
  crypto_generichash_init(&state_->state, nullptr, 0, std::tuple_size_v<Digest>);
}

ContentHasher::~ContentHasher() = default;

ContentHasher& ContentHasher::bytes(const void* data, std::size_t size) {
  crypto_generichash_update(&state_->state, static_cast<const unsigned char*>(data), size);
  return *this;
}

Digest ContentHasher::finish() {
  Digest digest{};
  crypto_generichash_final(&state_->state, digest.data(), digest.size());
  return digest;
}

Digest digest_of(const void* data, std::size_t size) {
  ContentHasher hasher;
  hasher.bytes(data, size);
  return hasher.finish();
}

}  // namespace cohaptic
