#include "common/laparoscopy/forceps_jaws.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <numbers>

#include "common/util/error.h"

namespace cohaptic {
namespace {

Eigen::Vector3d jaw_tip(const ForcepsGeometry& geometry, const ShaftFrame& shaft, int jaw,
                        double angle) noexcept {
  const double side = jaw == 0 ? 1.0 : -1.0;
  return shaft.tool + geometry.jaw_length *
                          (std::cos(angle) * shaft.axis + side * std::sin(angle) * shaft.opening);
}

}  // namespace

ForcepsJaws open_forceps(const ForcepsGeometry& geometry) {
  const auto positive = [](double x) { return x > 0 && std::isfinite(x); };
  if (!positive(geometry.jaw_length))
    throw Error(fmt::format("forceps: jaw_length is {} m, expected positive and finite",
                            geometry.jaw_length));
  if (!positive(geometry.open_angle) || !(geometry.open_angle < std::numbers::pi / 2))
    throw Error(
        fmt::format("forceps: open_angle is {} rad, expected in (0, pi/2)", geometry.open_angle));
  if (!positive(geometry.closing_step))
    throw Error(fmt::format("forceps: closing_step is {} rad, expected positive and finite",
                            geometry.closing_step));
  ForcepsJaws jaws;
  jaws.angle = {geometry.open_angle, geometry.open_angle};
  return jaws;
}

std::array<Eigen::Vector3d, 2> jaw_tips(const ForcepsGeometry& geometry, const ShaftFrame& shaft,
                                        const ForcepsJaws& jaws) noexcept {
  return {jaw_tip(geometry, shaft, 0, jaws.angle[0]), jaw_tip(geometry, shaft, 1, jaws.angle[1])};
}

void step_forceps(const ForcepsGeometry& geometry, const ShaftFrame& shaft, bool closing,
                  const AabbTree& surface, ForcepsJaws& jaws) noexcept {
  if (!closing) {
    jaws = ForcepsJaws{};
    jaws.angle = {geometry.open_angle, geometry.open_angle};
    return;
  }
  if (jaws.grasping) return;  // held until release
  for (int k = 0; k < 2; ++k) {
    const auto jaw = static_cast<std::size_t>(k);
    if (jaws.stopped[jaw] || jaws.angle[jaw] <= 0) continue;
    const double angle = std::max(jaws.angle[jaw] - geometry.closing_step, 0.0);
    const Eigen::Vector3d tip = jaw_tip(geometry, shaft, k, angle);
    jaws.angle[jaw] = angle;
    const AabbCrossing hit = surface.first_crossing(shaft.tool, tip);
    if (hit.triangle < 0) continue;
    jaws.stopped[jaw] = true;
    jaws.contact[jaw] = shaft.tool + hit.crossing.t * (tip - shaft.tool);
  }
  if (jaws.stopped[0] && jaws.stopped[1]) {
    jaws.grasping = true;
    jaws.grasp_point = 0.5 * (jaws.contact[0] + jaws.contact[1]);
    jaws.tool_at_grasp = shaft.tool;
  }
}

}  // namespace cohaptic
