#include "client/device/make_device.h"

#include <charconv>
#include <filesystem>
#include <fmt/format.h>
#include <functional>

#include "client/device/bridge_device.h"
#include "client/device/recorded_motion.h"
#include "common/haptics/hand_model.h"
#include "common/haptics/scripted_device.h"
#include "common/haptics/trajectory.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

struct DeviceKind {
  const char* prefix;  // before the first ':'
  const char* usage;   // the whole form, for messages
  std::function<std::unique_ptr<HapticDevice>(const std::string& args, double force_limit)> make;
  std::function<std::optional<Trajectory>(const std::string& args)> path;  // checks the args
};

std::uint16_t parse_port(const std::string& text, const std::string& spec) {
  unsigned value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end || value < 1 || value > 65535)
    throw Error(
        fmt::format("device '{}': expected a port from 1 to 65535, found '{}'", spec, text));
  return static_cast<std::uint16_t>(value);
}

BridgeOptions bridge_options(const std::string& args, const std::string& spec) {
  BridgeOptions options;
  const auto colon = args.rfind(':');
  if (colon == std::string::npos) {
    options.port = parse_port(args, spec);
  } else {
    std::string host = args.substr(0, colon);
    if (host.size() >= 2 && host.front() == '[' && host.back() == ']')
      host = host.substr(1, host.size() - 2);
    if (host.empty()) throw Error(fmt::format("device '{}': expected a host before ':PORT'", spec));
    options.host = host;
    options.port = parse_port(args.substr(colon + 1), spec);
  }
  return options;
}

// A replay's FILE may contain ':' itself: the whole is the file if there is one by that
// name, otherwise the text after the last ':' is the user.
Trajectory replayed_motion(const std::string& args) {
  const auto colon = args.rfind(':');
  std::error_code ignored;
  const bool has_user = colon != std::string::npos && colon + 1 < args.size() &&
                        !std::filesystem::exists(args, ignored);
  return recorded_motion(has_user ? args.substr(0, colon) : args,
                         has_user ? args.substr(colon + 1) : "");
}

// One entry per kind.
const std::vector<DeviceKind>& kinds() {
  static const std::vector<DeviceKind> table{
      {"script", "script:FILE        play the trajectory in FILE (open loop)",
       [](const std::string& file, double limit) -> std::unique_ptr<HapticDevice> {
         return std::make_unique<ScriptedDevice>(load_trajectory(file), limit);
       },
       [](const std::string& file) -> std::optional<Trajectory> { return load_trajectory(file); }},
      {"hand",
       "hand:FILE          a mass-spring-damper hand tracking the trajectory in FILE (closed loop)",
       [](const std::string& file, double limit) -> std::unique_ptr<HapticDevice> {
         Trajectory reference = load_trajectory(file);
         const HandParameters parameters = load_hand_parameters(file).value_or(HandParameters{});
         return std::make_unique<HandModelDevice>(std::move(reference), parameters, limit);
       },
       [](const std::string& file) -> std::optional<Trajectory> {
         load_hand_parameters(file);
         return load_trajectory(file);
       }},
      {"bridge",
       "bridge:[HOST:]PORT an external program sending poses to UDP HOST:PORT (default host "
       "127.0.0.1)",
       [](const std::string& args, double limit) {
         return std::make_unique<BridgeDevice>(bridge_options(args, "bridge:" + args), limit);
       },
       [](const std::string& args) -> std::optional<Trajectory> {
         bridge_options(args, "bridge:" + args);
         return std::nullopt;
       }},
      {"replay",
       "replay:FILE[:USER] the hand motion of a recording: a client's own, or a server's USER "
       "(slot or name; open loop)",
       [](const std::string& args, double limit) -> std::unique_ptr<HapticDevice> {
         return std::make_unique<ScriptedDevice>(replayed_motion(args), limit);
       },
       [](const std::string& args) -> std::optional<Trajectory> { return replayed_motion(args); }},
  };
  return table;
}

}  // namespace

std::vector<std::string> device_spec_forms() {
  std::vector<std::string> out;
  for (const DeviceKind& kind : kinds()) out.emplace_back(kind.usage);
  return out;
}

namespace {

// The kind `spec` names and its arguments; throws Error listing the forms if none.
std::pair<const DeviceKind*, std::string> device_kind(const std::string& spec) {
  const auto colon = spec.find(':');
  if (colon != std::string::npos && colon + 1 < spec.size()) {
    const std::string prefix = spec.substr(0, colon);
    for (const DeviceKind& kind : kinds())
      if (prefix == kind.prefix) return {&kind, spec.substr(colon + 1)};
  }
  std::string forms;
  for (const DeviceKind& kind : kinds()) forms += fmt::format("\n  {}", kind.usage);
  throw Error(fmt::format("unknown device '{}'; accepted forms:{}", spec, forms));
}

}  // namespace

std::unique_ptr<HapticDevice> make_device(const std::string& spec, double force_limit) {
  const auto [kind, args] = device_kind(spec);
  return kind->make(args, force_limit);
}

std::optional<Trajectory> device_path(const std::string& spec) {
  const auto [kind, args] = device_kind(spec);
  return kind->path(args);
}

}  // namespace cohaptic
