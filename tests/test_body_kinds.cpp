// The body kinds are listed once (common/kinds/body_kinds.h) and every per-kind variant
// follows that list: alternative i of the scene's spec, the model, the simulation, the IR
// body, the prepared body and the evaluator's state is one kind. Checked at compile time for
// the types, and at run time on an IR of each kind from the fuzzer's seeds: the prepared body
// and the state made for it are of the IR's kind, and an evaluation handed a state of another
// kind gives a zero force flagged non-finite, never another kind's answer. The haptic path's
// visit by index (common/util/visit_held.h) on a variant of each state.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "common/ir/evaluate_force.h"
#include "common/model/model.h"
#include "common/sim/scene_simulation.h"
#include "common/util/overloaded.h"
#include "common/util/visit_held.h"
#include "support/ir_seed.h"

namespace cohaptic::body_kinds_test {

template <class Kind, class Variant>
using Alternative = std::variant_alternative_t<body_kind_index<Kind>, Variant>;

static_assert(kBodyKindCount == std::variant_size_v<IrBody>);
static_assert(std::is_same_v<Alternative<LinearElasticKind, BodySpec>, ElasticObjectSpec>);
static_assert(std::is_same_v<Alternative<LinearElasticKind, BodyModel>, ElasticBody>);
static_assert(std::is_same_v<Alternative<LinearElasticKind, BodySimulation>, Simulation>);
static_assert(std::is_same_v<Alternative<LinearElasticKind, IrBody>, CondensedFemIr>);
static_assert(std::is_same_v<Alternative<LinearElasticKind, PreparedBody>, PreparedFem>);
static_assert(std::is_same_v<Alternative<LinearElasticKind, EvaluationBody>, FemEvaluation>);
static_assert(std::is_same_v<Alternative<MassSpringKind, BodyModel>, MassSpringModel>);
static_assert(std::is_same_v<Alternative<MassSpringKind, IrBody>, MassSpringIr>);
static_assert(std::is_same_v<Alternative<HomeSpringKind, BodySimulation>, HomeSpringSimulation>);
static_assert(std::is_same_v<Alternative<HomeSpringKind, EvaluationBody>, HomeSpringEvaluation>);
static_assert(std::is_same_v<Alternative<SeparationKind, BodySpec>, SeparationObjectSpec>);
static_assert(std::is_same_v<Alternative<SeparationKind, PreparedBody>, PreparedSeparation>);

struct Seed {
  std::string name;
  std::size_t kind;
  bool moves;  // evaluation_moves_the_body
};

const std::vector<Seed> kSeeds = {
    {"smallest", body_kind_index<LinearElasticKind>, false},
    {"sphere", body_kind_index<LinearElasticKind>, false},
    {"mass_spring", body_kind_index<MassSpringKind>, true},
    {"home_spring", body_kind_index<HomeSpringKind>, true},  // viscous: its vertex moves
    {"separation", body_kind_index<SeparationKind>, true},
};

TEST(BodyKinds, ThePreparedBodyAndTheEvaluatorStateAreOfTheIrsKind) {
  for (const Seed& seed : kSeeds) {
    SCOPED_TRACE(seed.name);
    const PreparedIR prepared = testing::prepared_ir_seed(seed.name);
    const EvaluationState state = make_evaluation_state(prepared);
    EXPECT_EQ(prepared.ir.body.index(), seed.kind);
    EXPECT_EQ(prepared.body.index(), seed.kind);
    EXPECT_EQ(state.body.index(), seed.kind);
    EXPECT_EQ(evaluation_moves_the_body(state), seed.moves);
  }
  // An FEM body's evaluator keeps a contact solve under the sphere model only.
  EXPECT_FALSE(
      std::get<FemEvaluation>(make_evaluation_state(testing::prepared_ir_seed("smallest")).body)
          .sphere.has_value());
  EXPECT_TRUE(
      std::get<FemEvaluation>(make_evaluation_state(testing::prepared_ir_seed("sphere")).body)
          .sphere.has_value());
}

TEST(BodyKinds, AStateOfAnotherKindGivesAZeroForceFlaggedNonFinite) {
  const Eigen::Vector3d far_away(1.0, 1.0, 1.0);  // [m]: touching none of the seeds' bodies
  std::vector<PreparedIR> prepared;
  for (const Seed& seed : kSeeds) prepared.push_back(testing::prepared_ir_seed(seed.name));
  for (std::size_t i = 0; i < prepared.size(); ++i)
    for (std::size_t j = 0; j < prepared.size(); ++j) {
      if (i != j && kSeeds[i].kind == kSeeds[j].kind) continue;  // the FEM seeds: two models
      SCOPED_TRACE(kSeeds[i].name + " evaluated with the state of " + kSeeds[j].name);
      EvaluationState state = make_evaluation_state(prepared[j]);
      const ForceSample sample = evaluate_force(prepared[i], state, far_away, {}, 1e-3);
      EXPECT_TRUE(sample.force.isZero());
      EXPECT_EQ((sample.flags & kNonFinite) != 0, kSeeds[i].kind != kSeeds[j].kind);
    }
}

// An alternative whose construction throws: emplacing it leaves the variant valueless (its
// own copy makes it not trivially copyable, so the library cannot build it aside first).
struct RefusesConstruction {
  RefusesConstruction() { throw std::runtime_error("refused"); }
  RefusesConstruction(const RefusesConstruction&) {}
  RefusesConstruction& operator=(const RefusesConstruction&) = default;
};

// The haptic path's visit (remote_count, remote_user) finds the held alternative by its
// index, and a valueless variant, where std::visit would throw, gives the fallback.
TEST(VisitHeld, CallsTheHeldAlternativesHandlerAndGivesTheFallbackForAValuelessVariant) {
  using Held = std::variant<int, double, RefusesConstruction>;
  const auto which = Overloaded{[](int) { return 1; }, [](double) { return 2; },
                                [](const RefusesConstruction&) { return 3; }};
  Held held = 5;
  EXPECT_EQ(visit_held(held, which, -1), 1);
  held = 2.5;
  EXPECT_EQ(visit_held(held, which, -1), 2);
  EXPECT_THROW(held.emplace<RefusesConstruction>(), std::runtime_error);
  ASSERT_TRUE(held.valueless_by_exception());
  EXPECT_EQ(visit_held(held, which, -1), -1);
}

}  // namespace cohaptic::body_kinds_test
