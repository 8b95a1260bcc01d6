// Simulation options for comparing forces with an independent answer: no force limit, so
// that a clamp never hides a difference.
#pragma once

#include <limits>

#include "common/sim/simulation.h"

namespace cohaptic::testing {

inline SimulationOptions unlimited_options(ContactModel model, int step_delay_nodes = 0,
                                           int patch_rings = 1,
                                           IrPrecision precision = IrPrecision::f64) {
  SimulationOptions options;
  options.ir.contact_model = model;
  options.ir.patch_rings = patch_rings;
  options.ir.precision = precision;
  options.ir.force_limit = std::numeric_limits<double>::infinity();
  options.step_delay_nodes = step_delay_nodes;
  return options;
}

}  // namespace cohaptic::testing
