// The keys of a `model: mass_spring` scene object (docs/mass-spring.md "Mass-spring objects"),
// validated with the scene loader's errors (file:line: key.path: expected ..., found ...).
#pragma once

#include "common/mass_spring/mass_spring_spec.h"
#include "common/util/yaml_cursor.h"

namespace cohaptic {

/// `c` is the object's map (with name and model); lengths are scaled by `scale` [m/unit].
MassSpringObjectSpec parse_mass_spring_object(const YamlCursor& c, double scale);

}  // namespace cohaptic
