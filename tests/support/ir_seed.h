// An IR of the IR fuzzer's seed corpus (tests/fuzz/corpus/ir/NAME, made by
// tests/fuzz/make_seeds.sh from the hand-written tests/fuzz/text_seeds/ir/*.txtpb), decoded
// completed (a seed sent as compliance rows is the first of its connection) and prepared as
// a client would: for tests that check the seeds reach the evaluation.
#pragma once

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "common/ir/client_condensation.h"
#include "common/ir/evaluate_force.h"
#include "proto/wire/ir_convert.h"

namespace cohaptic::testing {

inline PreparedIR prepared_ir_seed(const std::string& name) {
  std::ifstream in(std::string(COHAPTIC_SOURCE_DIR) + "/tests/fuzz/corpus/ir/" + name,
                   std::ios::binary);
  wire::IntermediateRepresentation message;
  EXPECT_TRUE(message.ParseFromIstream(&in)) << name;
  IntermediateRepresentation ir = wire::from_wire(message);
  if (auto* fem = std::get_if<CondensedFemIr>(&ir.body)) {
    ClientCondensation client;
    client.complete(*fem);
  }
  return prepare_ir(std::move(ir));
}

}  // namespace cohaptic::testing
