// BodyFrameState: one body's state as a live-view frame draws it. It is taken on the
// simulation thread after a step and must stay cheap there: a linear elastic body's loads
// (from the state solve of its frame, common/sim/elastic_states.h) and held nodes, a copy of
// a mass-spring body's node positions, a tissue's dents (P -> A per pressing user), a
// separating tissue's separated shares and grooves (it has no displacement field and is
// drawn at rest). The view's thread turns it into the displacement of the body's shown
// nodes (shown_scene.h). Units: m.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <variant>
#include <vector>

#include "common/separation/separation_state.h"
#include "common/sim/loaded_columns.h"
#include "common/sim/scene_simulation.h"
#include "view/shown_scene.h"

namespace cohaptic::view {

struct ElasticFrameState {
  std::vector<LoadedColumn> loads;  ///< the solved state's forces
  std::vector<int> held_nodes;      ///< B, the condensation's boundary nodes (volume indices)
};
struct MassSpringFrameState {
  Eigen::Matrix3Xd positions;  ///< every network node's [m]
};
struct TissueFrameState {
  std::vector<TissueDent> dents;
};
struct SeparationFrameState {
  std::vector<double> separated;       ///< per interface triangle, its separated share
  std::vector<GrooveSegment> grooves;  ///< the groove record's segments
  double separated_area = 0;           ///< [m^2]
};

/// One alternative per body kind: what is drawn of it.
using BodyFrameState =
    std::variant<ElasticFrameState, MassSpringFrameState, TissueFrameState, SeparationFrameState>;

/// Body `body`'s state (simulation thread): `columns` and `state` are its compliance columns
/// and its StateSolution when it is linear elastic (unused otherwise).
BodyFrameState body_frame_state(const BodySimulation& body, ComplianceColumns* columns,
                                const std::optional<StateSolution>& state);

/// The displacement of `part`'s shown nodes in `state` (any thread), one column per node [m].
Eigen::Matrix3Xd part_displacement(const BodyFrameState& state, const ShownPart& part,
                                   const ShownScene& scene);

}  // namespace cohaptic::view
