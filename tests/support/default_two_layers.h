// The separation tests' default scene, built once per test program: two 40 x 40 mm layers
// (a 4 mm flap on a 10 mm bed), 2 mm cells, every field and separation setting at its default.
#pragma once

#include "common/separation/separation_setup.h"

namespace cohaptic::testing {

inline const SeparationSetup& default_two_layers() {
  static const SeparationSetup setup =
      make_two_layer_setup(TwoLayerBoxes{}, FieldSettings{}, SeparationSettings{});
  return setup;
}

}  // namespace cohaptic::testing
