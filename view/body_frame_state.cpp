#include "view/body_frame_state.h"

#include "common/util/error.h"

namespace cohaptic::view {
namespace {

struct BodyFrameStateTaker {
  ComplianceColumns* columns;
  const std::optional<StateSolution>& state;

  BodyFrameState operator()(const Simulation& body) const {
    if (!columns || !state)
      throw Error("live view: a linear elastic body's frame needs its columns and its state solve");
    return ElasticFrameState{loaded_columns(*columns, *state),
                             body.condensation().boundary_nodes()};
  }
  BodyFrameState operator()(const MassSpringSimulation& body) const {
    return MassSpringFrameState{body.state().positions};
  }
  BodyFrameState operator()(const HomeSpringSimulation& body) const {
    return TissueFrameState{body.dents()};
  }
  BodyFrameState operator()(const SeparationSimulation& body) const {
    const SeparationState& separation = body.state();
    const auto grooves = separation.groove.segments.begin();
    return SeparationFrameState{
        separation.separated,
        {grooves, grooves + static_cast<std::ptrdiff_t>(separation.groove.count)},
        separation.separated_area};
  }
};

struct PartDisplacement {
  const ShownPart& part;
  const ShownScene& scene;

  Eigen::Matrix3Xd operator()(const ElasticFrameState& state) const {
    return displacement_of_rows(state.loads, part.row_positions);
  }
  Eigen::Matrix3Xd operator()(const MassSpringFrameState& state) const {
    Eigen::Matrix3Xd u(3, part.size());
    for (int k = 0; k < part.size(); ++k)
      u.col(k) = state.positions.col(part.nodes[static_cast<std::size_t>(k)]) -
                 scene.rest.col(part.offset + k);
    return u;
  }
  Eigen::Matrix3Xd operator()(const TissueFrameState& state) const {
    return dented_surface(*part.display, state.dents) -
           part.display->rest;  // every vertex is shown, in order
  }
  Eigen::Matrix3Xd operator()(const SeparationFrameState&) const {
    return Eigen::Matrix3Xd::Zero(3, part.size());
  }
};

}  // namespace

BodyFrameState body_frame_state(const BodySimulation& body, ComplianceColumns* columns,
                                const std::optional<StateSolution>& state) {
  return std::visit(BodyFrameStateTaker{columns, state}, body);
}

Eigen::Matrix3Xd part_displacement(const BodyFrameState& state, const ShownPart& part,
                                   const ShownScene& scene) {
  return std::visit(PartDisplacement{part, scene}, state);
}

}  // namespace cohaptic::view
