#include "common/sim/scene_simulation.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <type_traits>

#include "common/util/error.h"
#include "common/util/overloaded.h"

namespace cohaptic {
namespace {

// Makes body i's simulation from its compiled body.
struct SimulationMaker {
  const Model& model;
  ComplianceColumns* columns;
  const std::vector<ToolSpec>& tools;
  const SimulationOptions& options;
  int object;
  BodySimulation operator()(const ElasticBody& body) const {
    if (!columns)
      throw Error(fmt::format(
          "scene simulation: no compliance columns for the linear elastic object '{}'", body.name));
    return BodySimulation(std::in_place_type<Simulation>, body, model.obstacles, *columns, tools,
                          options);
  }
  BodySimulation operator()(const MassSpringModel& body) const {
    return BodySimulation(std::in_place_type<MassSpringSimulation>, body, object, tools,
                          model.scene.haptic.force_limit_n, 1 / model.scene.haptic.rate_hz);
  }
  BodySimulation operator()(const HomeSpringBody& body) const {
    return BodySimulation(std::in_place_type<HomeSpringSimulation>, body, object, tools,
                          model.scene.haptic.force_limit_n);
  }
  BodySimulation operator()(const SeparationModel& body) const {
    return BodySimulation(std::in_place_type<SeparationSimulation>, body, object, tools,
                          model.scene.haptic.force_limit_n);
  }
};

// The index of the body named `name` (the loader checked that it exists).
int body_index(const Model& model, const std::string& name) {
  for (int i = 0; i < static_cast<int>(model.bodies.size()); ++i)
    if (body_name(model, i) == name) return i;
  throw Error(fmt::format("scene simulation: no object named '{}'", name));
}

}  // namespace

SceneSimulation::SceneSimulation(const Model& model, std::span<ComplianceColumns* const> columns,
                                 const std::vector<ToolSpec>& tools,
                                 const SimulationOptions& options)
    : model_(model), users_(tools.size()), columns_(columns.begin(), columns.end()) {
  if (columns.size() != model.bodies.size())
    throw Error(fmt::format("scene simulation: {} compliance column sets for {} bodies",
                            columns.size(), model.bodies.size()));
  bodies_.reserve(model.bodies.size());
  for (std::size_t i = 0; i < model.bodies.size(); ++i)
    bodies_.push_back(std::visit(
        SimulationMaker{model, columns[i], tools, options, static_cast<int>(i)}, model.bodies[i]));
  for (const InteractionSpec& spec : model.scene.interactions) {
    const int front = body_index(model, spec.front);
    const int behind = body_index(model, spec.behind);
    const BodyModel& front_model = model.bodies[static_cast<std::size_t>(front)];
    const auto* behind_body =
        std::get_if<ElasticBody>(&model.bodies[static_cast<std::size_t>(behind)]);
    if (const auto* network = std::get_if<MassSpringModel>(&front_model); network && behind_body)
      interactions_.push_back(make_body_interaction(front, *network, behind, *behind_body));
    else if (std::holds_alternative<ElasticBody>(front_model) && behind_body)
      add_fem_pair(spec, front, behind, options);
    else
      throw Error(fmt::format(
          "{}: the interaction needs a mass-spring or linear elastic front and a linear elastic "
          "behind object",
          spec.where));
  }
}

void SceneSimulation::add_fem_pair(const InteractionSpec& spec, int front, int behind,
                                   const SimulationOptions& options) {
  // The coupled solve holds each tool's dofs where they are: the translation model's contact.
  if (options.ir.contact_model != ContactModel::node_translation)
    throw Error(fmt::format(
        "{}: a linear elastic front object presses on another under the translation contact model "
        "only, and this scene's is '{}' (haptic: {{contact_model: translation}})",
        spec.where, contact_model_name(options.ir.contact_model)));
  // Each pair sets both bodies' applied loads: a body in two pairs would lose one's.
  for (const FemPairInteraction& pair : fem_pairs_)
    for (const int body : {front, behind})
      if (body == pair.front || body == pair.behind)
        throw Error(
            fmt::format("{}: object '{}' is in an earlier pair of linear elastic objects already "
                        "(one such pair "
                        "per object)",
                        spec.where, body_name(model_, body)));
  const auto& front_body = std::get<ElasticBody>(model_.bodies[static_cast<std::size_t>(front)]);
  const auto& behind_body = std::get<ElasticBody>(model_.bodies[static_cast<std::size_t>(behind)]);
  fem_pairs_.push_back(make_fem_pair_interaction(front, front_body, behind, behind_body));
}

void SceneSimulation::couple(FemPairInteraction& pair) {
  const auto front = static_cast<std::size_t>(pair.front);
  const auto behind = static_cast<std::size_t>(pair.behind);
  couple_fem_pair(pair, std::get<Simulation>(bodies_[front]),
                  std::get<ElasticBody>(model_.bodies[front]), *columns_[front],
                  std::get<Simulation>(bodies_[behind]),
                  std::get<ElasticBody>(model_.bodies[behind]), *columns_[behind]);
}

StepReport SceneSimulation::step_fem_body(int body, Simulation& simulation, double time) {
  simulation.update_held_set();
  // The front of a pair pushes with its tools' contacts and held set known, before its IRs.
  for (FemPairInteraction& pair : fem_pairs_)
    if (pair.front == body) couple(pair);
  return simulation.build_irs(time);
}

bool SceneSimulation::condenses_over_support(int body_index) const {
  const auto* fem = std::get_if<Simulation>(&body(body_index));
  return fem && fem->support();
}

void SceneSimulation::run_interactions() {
  for (BodyInteraction& interaction : interactions_) {
    auto& front =
        std::get<MassSpringSimulation>(bodies_[static_cast<std::size_t>(interaction.front)]);
    const auto& behind =
        std::get<ElasticBody>(model_.bodies[static_cast<std::size_t>(interaction.behind)]);
    front.set_backing(
        step_body_interaction(interaction, front.state().positions, front.body(), behind,
                              *columns_[static_cast<std::size_t>(interaction.behind)]));
  }
}

void SceneSimulation::set_tool(int user, const Eigen::Vector3d& position, std::uint32_t buttons) {
  UserState& state = users_[static_cast<std::size_t>(user)];
  state.known = position.allFinite();
  state.position = position;
  state.buttons = buttons;
}

void SceneSimulation::clear_tool(int user) { users_[static_cast<std::size_t>(user)].known = false; }

bool SceneSimulation::pressing(int user) const {
  return std::visit([user](const auto& simulation) { return simulation.pressing(user); },
                    body(body_of(user)));
}

double SceneSimulation::distance_to_body(int body_index, const Eigen::Vector3d& point) const {
  return std::visit(
      Overloaded{
          [&](const Simulation&) {
            const ElasticBody& elastic =
                std::get<ElasticBody>(model_.bodies[static_cast<std::size_t>(body_index)]);
            double nearest = std::numeric_limits<double>::infinity();
            for (int node : elastic.touchable_nodes)
              nearest = std::min(nearest, (elastic.mesh.nodes.col(node) - point).norm());
            return nearest;
          },
          [&](const MassSpringSimulation& network) { return network.distance_to_surface(point); },
          [&](const HomeSpringSimulation& tissue) { return tissue.distance_to_surface(point); },
          [&](const SeparationSimulation& layers) { return layers.distance_to_interface(point); }},
      body(body_index));
}

void SceneSimulation::assign_bodies() {
  if (bodies_.size() < 2) return;
  for (int u = 0; u < user_count(); ++u) {
    UserState& user = users_[static_cast<std::size_t>(u)];
    if (!user.known || pressing(u)) continue;
    int nearest = user.body;
    double best = distance_to_body(user.body, user.position);
    for (int b = 0; b < body_count(); ++b)
      if (const double distance = distance_to_body(b, user.position); distance < best) {
        best = distance;
        nearest = b;
      }
    if (nearest == user.body) continue;
    user.body = nearest;
    const std::uint64_t epoch = user.ir ? user.ir->ir.epoch : 0;
    std::visit([&](auto& simulation) { simulation.continue_epochs(u, epoch); },
               bodies_[static_cast<std::size_t>(nearest)]);
  }
}

void SceneSimulation::set_step_delay_nodes(int nodes) {
  for (BodySimulation& body : bodies_)
    if (auto* fem = std::get_if<Simulation>(&body)) fem->set_step_delay_nodes(nodes);
}

StepReport SceneSimulation::step(double time) {
  period_ = started_ ? time - time_ : 0;
  started_ = true;
  time_ = time;
  assign_bodies();
  run_interactions();
  StepReport report;
  for (int b = 0; b < body_count(); ++b) {
    BodySimulation& simulation = bodies_[static_cast<std::size_t>(b)];
    std::visit(
        [&](auto& body_simulation) {
          for (int u = 0; u < user_count(); ++u) {
            const UserState& user = users_[static_cast<std::size_t>(u)];
            if (!user.known || user.body != b)
              body_simulation.clear_tool(u);
            else if constexpr (requires {
                                 body_simulation.set_tool(u, user.position, user.buttons);
                               })
              body_simulation.set_tool(u, user.position,
                                       user.buttons);  // a body whose tools have buttons
            else
              body_simulation.set_tool(u, user.position);
          }
          if constexpr (std::is_same_v<std::remove_cvref_t<decltype(body_simulation)>, Simulation>)
            report += step_fem_body(b, body_simulation, time);
          else
            report += body_simulation.step(time);
        },
        simulation);
  }
  for (int u = 0; u < user_count(); ++u) {
    UserState& user = users_[static_cast<std::size_t>(u)];
    auto latest =
        std::visit([u](const auto& simulation) { return simulation.ir(u); }, body(user.body));
    // A body the user left long ago may still hold an older IR for it: never hand one back.
    user.changed =
        latest && latest != user.ir && (!user.ir || latest->ir.epoch > user.ir->ir.epoch);
    if (user.changed) user.ir = std::move(latest);
  }
  return report;
}

ForceSample SceneSimulation::force(int user) {
  return std::visit(
      Overloaded{[&](Simulation& fem) { return fem.force(user); },
                 [&](MassSpringSimulation& network) { return network.force(user, period_); },
                 [&](HomeSpringSimulation& tissue) { return tissue.force(user); },
                 [&](SeparationSimulation& layers) { return layers.force(user); }},
      bodies_[static_cast<std::size_t>(body_of(user))]);
}

const Simulation& SceneSimulation::single_elastic() const {
  single_elastic_body(model_);  // throws naming the scene when it is not one linear elastic object
  return std::get<Simulation>(bodies_.front());
}

Simulation& SceneSimulation::single_elastic() {
  single_elastic_body(model_);
  return std::get<Simulation>(bodies_.front());
}

}  // namespace cohaptic
