// An IR as a client receives it: serialised to the wire's protobuf and parsed back.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "proto/wire/ir_convert.h"

namespace cohaptic::testing {

inline IntermediateRepresentation over_the_wire(const IntermediateRepresentation& ir) {
  std::string bytes;
  EXPECT_TRUE(wire::to_wire(ir).SerializeToString(&bytes));
  wire::IntermediateRepresentation parsed;
  EXPECT_TRUE(parsed.ParseFromString(bytes));
  return wire::from_wire(parsed);
}

}  // namespace cohaptic::testing
