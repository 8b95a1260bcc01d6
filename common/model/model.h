// Model: everything compiled once from a Scene and never changed afterwards (after
// MuJoCo's mjModel): the scene itself, one compiled body per scene object (a variant over
// the body kinds, in the scene's order) and the rigid obstacles.
//
// Functions that only need the model take it as const&. What the loops mutate lives in the
// simulations (common/sim) and the clients' evaluation state. Units: SI.
#pragma once

#include <variant>
#include <vector>

#include "common/contact/obstacle.h"
#include "common/kinds/body_kinds.h"
#include "common/model/elastic_body.h"
#include "common/model/home_spring_body.h"
#include "common/model/mass_spring_body.h"
#include "common/model/separation_body.h"
#include "common/scene/scene.h"

namespace cohaptic {

/// A compiled scene object: one alternative per body kind (common/kinds/body_kinds.h).
using BodyModel =
    PerKind<ForKind<LinearElasticKind, ElasticBody>, ForKind<MassSpringKind, MassSpringModel>,
            ForKind<HomeSpringKind, HomeSpringBody>,
            ForKind<SeparationKind, SeparationModel>>::variant;

struct Model {
  Scene scene;
  std::vector<BodyModel> bodies;  ///< bodies[i] compiled from scene.objects[i]
  std::vector<Obstacle> obstacles;
};

/// Compiles `scene`: every object, then the obstacles. Throws the errors of the body
/// builders (SceneError, MeshError, NumericalError) and Error for an unreadable obstacle.
Model build_model(const Scene& scene);

/// The scene object's name of body `index`.
const std::string& body_name(const Model& model, int index);

/// Body `index` as an FEM body. Throws Error naming the object and its model when it is
/// another kind, or when there is no such body: for tools that only work on FEM bodies.
const ElasticBody& elastic_body(const Model& model, int index);

/// The scene's only body, as an FEM body: for the tools that work on one FEM object (the
/// probe, the trade-off, the display). Throws Error naming the scene when it has several
/// objects or its object is of another kind.
const ElasticBody& single_elastic_body(const Model& model);

}  // namespace cohaptic
