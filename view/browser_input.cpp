#include "view/browser_input.h"

#include <algorithm>
#include <cctype>
#include <cstddef>

#include "view/view_token.h"

namespace cohaptic::view {
namespace {

// Compares without stopping at the first difference, so the time taken tells nothing.
bool same_secret(const std::string& a, const std::string& b) {
  unsigned char difference = a.size() == b.size() ? 0 : 1;
  for (std::size_t i = 0; i < a.size(); ++i)
    difference |= static_cast<unsigned char>(a[i] ^ b[i % std::max<std::size_t>(b.size(), 1)]);
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

bool names_this_machine(const std::string& host) {
  std::string name = host;
  if (!name.empty() && name.front() == '[') {  // [v6]:port
    const std::size_t close = name.find(']');
    if (close == std::string::npos) return false;
    name = name.substr(1, close - 1);
  } else if (std::count(name.begin(), name.end(), ':') == 1) {
    name = name.substr(0, name.find(':'));
  }
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return name == "localhost" || is_loopback(name);
}

std::string handshake_refusal(const std::string& resource, const std::string& origin,
                              const std::string& host, const std::string& token) {
  if (resource.substr(0, resource.find('?')) != "/ws") return "not the data path /ws";
  if (!token.empty() && !same_secret(query_value(resource, "token"), token))
    return "wrong or missing token";
  // Without a token only this machine's browsers may watch: a page whose name was made to
  // resolve here (DNS rebinding) sends its own name as Host.
  if (token.empty() && !names_this_machine(host))
    return "a request for the host '" + host + "' (not this machine's name)";
  if (!origin.empty() && origin != "http://" + host) return "a page from " + origin;
  return "";
}

std::optional<Command> parse_command(const std::string& payload) {
  Command command;
  if (!command.ParseFromString(payload) || command.body_case() == Command::BODY_NOT_SET)
    return std::nullopt;
  return command;
}

}  // namespace cohaptic::view
