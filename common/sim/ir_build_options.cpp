#include "common/sim/ir_build_options.h"

namespace cohaptic {

IrBuildOptions ir_build_options(const HapticSettings& haptic) {
  IrBuildOptions options;
  options.patch_rings = haptic.patch_rings;
  options.contact_model = haptic.contact_model;
  options.force_limit = haptic.force_limit_n;
  options.boundary_truncation = haptic.boundary_truncation;
  return options;
}

}  // namespace cohaptic
