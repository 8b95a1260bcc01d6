// The IR builder's options a scene's haptic settings ask for: the bridge from the scene file
// to common/ir/, which knows nothing of scenes.
#pragma once

#include "common/ir/build_ir.h"
#include "common/scene/scene.h"

namespace cohaptic {

/// The IR settings `haptic` (a scene's) asks for, at f64 (the precision is the server's choice).
IrBuildOptions ir_build_options(const HapticSettings& haptic);

}  // namespace cohaptic
