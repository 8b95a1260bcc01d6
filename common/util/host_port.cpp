#include "common/util/host_port.h"

namespace cohaptic {

std::string parse_host_port(const std::string& text, std::string& host, std::uint16_t& port,
                            bool allow_any_port) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0) return "expected HOST:PORT, got '" + text + "'";
  int value = -1;
  try {
    std::size_t used = 0;
    value = std::stoi(text.substr(colon + 1), &used);
    if (used != text.size() - colon - 1) value = -1;
  } catch (const std::exception&) {
    value = -1;
  }
  if (value < (allow_any_port ? 0 : 1) || value > 65535)
    return "expected a port number " + std::string(allow_any_port ? "0" : "1") +
           "-65535 after ':' in '" + text + "'";
  host = text.substr(0, colon);
  port = static_cast<std::uint16_t>(value);
  return {};
}

}  // namespace cohaptic
