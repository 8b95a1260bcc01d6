// Asserts that an intermediate representation is refused, by from_wire or else by
// prepare_ir, with an Error whose message holds `reason`.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "common/ir/evaluate_force.h"
#include "common/util/error.h"
#include "proto/wire/ir_convert.h"

namespace cohaptic::testing {

inline void expect_refused(const IntermediateRepresentation& ir, const std::string& reason) {
  try {
    prepare_ir(ir);
    ADD_FAILURE() << "accepted; expected an error containing \"" << reason << "\"";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
  }
}

inline void expect_refused(const wire::IntermediateRepresentation& w, const std::string& reason) {
  try {
    expect_refused(wire::from_wire(w), reason);
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
  }
}

}  // namespace cohaptic::testing
