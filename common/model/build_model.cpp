#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "common/mesh/read_freesurfer.h"
#include "common/model/body_model_name.h"
#include "common/model/model.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

Obstacle load_obstacle(const ObstacleSpec& spec, double metres_per_unit) {
  Obstacle obstacle;
  obstacle.name = spec.name;
  obstacle.plane = spec.plane;
  if (!spec.surface_file.empty()) {
    obstacle.surface = read_freesurfer_ascii(spec.surface_file);
    obstacle.surface.vertices *= metres_per_unit;
    for (const std::string& finding : check_triangle_surface(obstacle.surface, "obstacle " + spec.name))
      spdlog::warn("{}", finding);
  }
  return obstacle;
}

// Compiles one scene object into the body of its kind.
struct BodyBuilder {
  const ObjectSpec& object;
  double metres_per_unit;
  double force_limit;  // the scene's haptic limit [N]
  BodyModel operator()(const ElasticObjectSpec& spec) const {
    return build_elastic_body(object, spec, metres_per_unit);
  }
  BodyModel operator()(const MassSpringObjectSpec& spec) const { return build_mass_spring_body(object.name, spec, object.where); }
  BodyModel operator()(const HomeSpringObjectSpec& spec) const {
    return build_home_spring_body(object.name, spec, object.where, metres_per_unit);
  }
  BodyModel operator()(const SeparationObjectSpec& spec) const {
    return build_separation_body(object.name, spec, force_limit, metres_per_unit, object.where);
  }
};

// The model name a user wrote for the body kind, for messages.
struct KindName {
  const char* operator()(const ElasticBody&) const { return "linear_elastic"; }
  const char* operator()(const MassSpringModel&) const { return "mass_spring"; }
  const char* operator()(const HomeSpringBody&) const { return "home_spring"; }
  const char* operator()(const SeparationModel&) const { return "separation"; }
};

}  // namespace

Model build_model(const Scene& scene) {
  Model model;
  model.scene = scene;
  for (const ObjectSpec& object : scene.objects)
    model.bodies.push_back(std::visit(BodyBuilder{object, scene.metres_per_unit, scene.haptic.force_limit_n}, object.body));
  for (const ObstacleSpec& spec : scene.obstacles) model.obstacles.push_back(load_obstacle(spec, scene.metres_per_unit));
  return model;
}

const std::string& body_name(const Model& model, int index) { return model.scene.objects.at(index).name; }

const char* body_model_name(const BodyModel& body) { return std::visit(KindName{}, body); }

const ElasticBody& elastic_body(const Model& model, int index) {
  if (index < 0 || index >= static_cast<int>(model.bodies.size()))
    throw Error(fmt::format("scene '{}' has {} objects: there is no object {}", model.scene.name, model.bodies.size(), index));
  if (const auto* body = std::get_if<ElasticBody>(&model.bodies[index])) return *body;
  throw Error(fmt::format("object '{}' is a {} body, and this needs a linear_elastic one", body_name(model, index),
                          body_model_name(model.bodies[index])));
}

const ElasticBody& single_elastic_body(const Model& model) {
  if (model.bodies.size() != 1)
    throw Error(fmt::format("scene '{}' has {} objects; this works on a scene with one linear_elastic object",
                            model.scene.name, model.bodies.size()));
  return elastic_body(model, 0);
}

}  // namespace cohaptic
