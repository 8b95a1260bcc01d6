#include "view/view_token.h"

#include <sodium.h>

#include <asio/ip/address.hpp>
#include <cctype>
#include <fstream>

#include "common/util/error.h"

namespace cohaptic::view {

bool is_loopback(const std::string& host) {
  asio::error_code error;
  const asio::ip::address address = asio::ip::make_address(host, error);
  return !error && address.is_loopback();
}

std::string random_token() {
  if (sodium_init() < 0) throw Error("view: libsodium could not be initialised");
  unsigned char bytes[16];
  randombytes_buf(bytes, sizeof bytes);
  char hex[2 * sizeof bytes + 1];
  sodium_bin2hex(hex, sizeof hex, bytes, sizeof bytes);
  return hex;
}

std::string access_token(const std::string& host,
                         const std::optional<std::filesystem::path>& token_file) {
  if (token_file) {
    std::ifstream in(*token_file);
    std::string token;
    if (!in || !std::getline(in, token))
      throw Error("view: cannot read the token file " + token_file->string());
    while (!token.empty() && (token.back() == '\r' || token.back() == ' ')) token.pop_back();
    if (token.size() < 16)
      throw Error("view: the token in " + token_file->string() + " is shorter than 16 characters");
    for (char c : token)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_')
        throw Error("view: the token in " + token_file->string() +
                    " may hold only letters, digits, '-' and '_'");
    return token;
  }
  return is_loopback(host) ? std::string() : random_token();
}

}  // namespace cohaptic::view
