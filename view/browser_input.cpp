#include "view/browser_input.h"

#include <algorithm>
#include <cstddef>

namespace cohaptic::view {
namespace {

// Compares without stopping at the first difference, so the time taken tells nothing.
bool same_secret(const std::string& a, const std::string& b) {
  unsigned char difference = a.size() == b.size() ? 0 : 1;
  for (std::size_t i = 0; i < a.size(); ++i) difference |= static_cast<unsigned char>(a[i] ^ b[i % std::max<std::size_t>(b.size(), 1)]);
  return difference == 0;
}

}  // namespace

std::string query_value(const std::string& resource, const std::string& name) {
  const std::size_t query = resource.find('?');
  if (query == std::string::npos) return "";
  std::size_t at = query + 1;
  while (at < resource.size()) {
    const std::size_t end = std::min(resource.find('&', at), resource.size());
    const std::string pair = resource.substr(at, end - at);
    if (pair.rfind(name + "=", 0) == 0) return pair.substr(name.size() + 1);
    at = end + 1;
  }
  return "";
}

std::string handshake_refusal(const std::string& resource, const std::string& origin, const std::string& host,
                              const std::string& token) {
  if (resource.substr(0, resource.find('?')) != "/ws") return "not the data path /ws";
  if (!token.empty() && !same_secret(query_value(resource, "token"), token)) return "wrong or missing token";
  if (!origin.empty() && origin != "http://" + host) return "a page from " + origin;
  return "";
}

std::optional<Command> parse_command(const std::string& payload) {
  Command command;
  if (!command.ParseFromString(payload) || command.body_case() == Command::BODY_NOT_SET) return std::nullopt;
  return command;
}

}  // namespace cohaptic::view
