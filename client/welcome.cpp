#include "client/welcome.h"

#include <fmt/format.h>

#include <cmath>

#include "common/util/error.h"

namespace cohaptic {

WelcomeInfo welcome_info(const wire::Welcome& welcome) {
  const auto fail = [](const std::string& what) {
    throw Error("welcome from the server: " + what);
  };
  if (welcome.slot() >= static_cast<std::uint32_t>(welcome.users_size()))
    fail(fmt::format("slot {} is not one of its {} user slots", welcome.slot(),
                     welcome.users_size()));
  if (welcome.protocol() != wire::P0 && welcome.protocol() != wire::P1)
    fail(fmt::format("protocol {} is neither P0 nor P1", static_cast<int>(welcome.protocol())));
  if (!(welcome.force_limit() > 0 && welcome.force_limit() <= 1000))
    fail(fmt::format("force_limit {} is not in (0, 1000] N", welcome.force_limit()));
  if (!(welcome.haptic_rate_hz() >= 1 && welcome.haptic_rate_hz() <= 100000))
    fail(fmt::format("haptic_rate_hz {} is not in [1, 100000] Hz", welcome.haptic_rate_hz()));
  if (!(welcome.ir_max_age_s() > 0 && std::isfinite(welcome.ir_max_age_s())))
    fail(
        fmt::format("ir_max_age_s {} is not a positive, finite time in s", welcome.ir_max_age_s()));

  WelcomeInfo info;
  info.slot = static_cast<int>(welcome.slot());
  info.scene_name = welcome.scene_name();
  info.scene_yaml = welcome.scene_yaml();
  info.protocol = welcome.protocol() == wire::P0 ? HapticProtocol::p0 : HapticProtocol::p1;
  info.force_limit = welcome.force_limit();
  info.haptic_rate_hz = welcome.haptic_rate_hz();
  info.ir_max_age_s = welcome.ir_max_age_s();
  info.user_count = welcome.users_size();
  const auto& v = welcome.surface().vertices();
  for (int i = 0; i + 2 < v.size(); i += 3) {
    const Eigen::Vector3d vertex(v[i], v[i + 1], v[i + 2]);
    if (vertex.allFinite()) info.surface_bounds.extend(vertex);
  }
  return info;
}

}  // namespace cohaptic
