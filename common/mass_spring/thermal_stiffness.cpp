#include "common/mass_spring/thermal_stiffness.h"

#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {

double thermal_stiffness_factor(const HeatedRegion& region) {
  const double factor =
      1 - region.coupling * region.expansion_coefficient * region.temperature_rise;
  if (!(factor > 0) || !(factor <= 1))
    throw Error(fmt::format(
        "heating by {} K with alpha_L {} /K and c {} scales the springs by {}: expected a factor "
        "in (0, 1]",
        region.temperature_rise, region.expansion_coefficient, region.coupling, factor));
  return factor;
}

int heat_springs(MassSpringNetwork& network, const HeatedRegion& region) {
  const double factor = thermal_stiffness_factor(region);
  auto inside = [&](int node) {
    const auto x = network.rest_positions.col(node);
    return (x.array() >= region.box_min.array()).all() &&
           (x.array() <= region.box_max.array()).all();
  };
  int heated = 0;
  for (Spring& spring : network.springs)
    if (inside(spring.a) && inside(spring.b)) {
      spring.stiffness *= factor;
      spring.damping *= factor;
      ++heated;
    }
  return heated;
}

}  // namespace cohaptic
