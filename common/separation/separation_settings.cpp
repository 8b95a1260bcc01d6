#include "common/separation/separation_settings.h"

#include <cmath>
#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {
namespace {

void require_positive(double value, const char* name) {
  if (!(value > 0) || !std::isfinite(value))
    throw Error(
        fmt::format("separation settings: {} must be a positive number, got {}", name, value));
}

}  // namespace

void validate(const SeparationSettings& settings) {
  require_positive(settings.fracture.toughness, "fracture.toughness (J_c)");
  require_positive(settings.fracture.normal_length, "fracture.normal_length (l_n)");
  require_positive(settings.fracture.tangential_length, "fracture.tangential_length (l_t)");
  if (!(settings.fracture.friction >= 0) || !std::isfinite(settings.fracture.friction))
    throw Error(fmt::format("separation settings: fracture.friction must be >= 0, got {}",
                            settings.fracture.friction));
  require_positive(settings.laser.power, "laser.power (P)");
  require_positive(settings.laser.absorbed_fraction, "laser.absorbed_fraction (alpha)");
  if (settings.laser.absorbed_fraction > 1)
    throw Error(fmt::format(
        "separation settings: laser.absorbed_fraction (alpha) must be at most 1, got {}",
        settings.laser.absorbed_fraction));
  require_positive(settings.laser.spot_diameter, "laser.spot_diameter (l_f)");
  require_positive(settings.laser.reach, "laser.reach");
  require_positive(settings.tissue.density, "tissue.density (rho)");
  require_positive(settings.tissue.specific_heat, "tissue.specific_heat (c_p)");
  if (!(settings.tissue.temperature_rise >= 0) || !std::isfinite(settings.tissue.temperature_rise))
    throw Error(fmt::format("separation settings: tissue.temperature_rise must be >= 0, got {}",
                            settings.tissue.temperature_rise));
  require_positive(settings.tissue.latent_heat, "tissue.latent_heat (H)");
  require_positive(settings.force_limit, "force_limit");
}

double vaporisation_energy_density(const TissueThermal& tissue) {
  return tissue.density * (tissue.specific_heat * tissue.temperature_rise + tissue.latent_heat);
}

double vaporisation_speed(const LaserSettings& laser, const TissueThermal& tissue) {
  return laser.absorbed_fraction * laser.power /
         (vaporisation_energy_density(tissue) * laser.spot_diameter * laser.spot_diameter);
}

}  // namespace cohaptic
