// The scene's `model:` name of a compiled body's kind, for messages and for what the live
// view tells the page about each object.
#pragma once

#include "common/model/model.h"

namespace cohaptic {

/// "linear_elastic", "mass_spring", "home_spring" or "separation": the scene's `model:` of
/// this body's kind.
const char* body_model_name(const BodyModel& body);

}  // namespace cohaptic
