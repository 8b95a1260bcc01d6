#include "view/view_messages.h"

#include <Eigen/Geometry>

#include "common/model/body_model_name.h"
#include "common/util/overloaded.h"

namespace cohaptic::view {
namespace {

void add_point(google::protobuf::RepeatedField<float>& out, const Eigen::Vector3d& p) {
  for (int axis = 0; axis < 3; ++axis) out.Add(static_cast<float>(p[axis]));
}

// A plane obstacle as a square around the object's projection on it, twice the object's size.
void add_plane(Obstacle& out, const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
               const Eigen::Matrix3Xd& nodes) {
  const Eigen::Vector3d centre = nodes.rowwise().mean();
  const Eigen::Vector3d on_plane = centre - normal.dot(centre - point) * normal;
  const double half = (nodes.rowwise().maxCoeff() - nodes.rowwise().minCoeff()).norm();
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  for (const auto& [a, b] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}})
    add_point(*out.mutable_vertices(), on_plane + half * (a * u + b * v));
  for (std::uint32_t index : {0u, 1u, 2u, 0u, 2u, 3u}) out.add_triangles(index);
}

}  // namespace

Scene view_scene(const Model& model, const ShownScene& shown, wire::Protocol protocol,
                 const record::InjectedDelays& injected, double frame_rate_hz,
                 const std::string& source) {
  Scene scene;
  scene.set_scene_name(model.scene.name);
  scene.set_units(model.scene.units);
  scene.set_metres_per_unit(model.scene.metres_per_unit);
  for (Eigen::Index node = 0; node < shown.rest.cols(); ++node)
    add_point(*scene.mutable_rest_positions(), shown.rest.col(node));
  for (const Triangle& tri : shown.triangles)
    for (int corner : tri) scene.add_triangles(static_cast<std::uint32_t>(corner));
  for (std::size_t body = 0; body < shown.parts.size(); ++body) {
    ShownObject* object = scene.add_objects();
    object->set_name(body_name(model, static_cast<int>(body)));
    object->set_model(body_model_name(model.bodies[body]));
    object->set_first_node(static_cast<std::uint32_t>(shown.parts[body].offset));
    object->set_node_count(static_cast<std::uint32_t>(shown.parts[body].size()));
    if (const auto* layers = std::get_if<SeparationModel>(&model.bodies[body])) {
      Interface* out = scene.add_interfaces();
      out->set_object(static_cast<std::uint32_t>(body));
      const SeparationPatch& patch = *layers->patch;
      for (Eigen::Index node = 0; node < patch.positions.cols(); ++node)
        add_point(*out->mutable_vertices(), patch.positions.col(node));
      for (const Triangle& tri : patch.triangles)
        for (int corner : tri) out->add_triangles(static_cast<std::uint32_t>(corner));
    }
  }
  for (std::size_t slot = 0; slot < model.scene.tools.size(); ++slot) {
    Tool* tool = scene.add_tools();
    tool->set_slot(static_cast<std::uint32_t>(slot));
    tool->set_name(model.scene.tools[slot].name);
    tool->set_radius(model.scene.tools[slot].radius);
  }
  for (const cohaptic::Obstacle& obstacle : model.obstacles) {
    Obstacle* out = scene.add_obstacles();
    out->set_name(obstacle.name);
    if (obstacle.plane) {
      add_plane(*out, obstacle.plane->first, obstacle.plane->second, shown.rest);
      continue;
    }
    for (Eigen::Index v = 0; v < obstacle.surface.vertices.cols(); ++v)
      add_point(*out->mutable_vertices(), obstacle.surface.vertices.col(v));
    for (const Triangle& tri : obstacle.surface.triangles)
      for (int corner : tri) out->add_triangles(static_cast<std::uint32_t>(corner));
  }
  scene.set_protocol(protocol);
  *scene.mutable_injected() = injected;
  scene.set_frame_rate_hz(frame_rate_hz);
  scene.set_force_limit(model.scene.haptic.force_limit_n);
  scene.set_source(source);
  return scene;
}

FrameState frame_state(const SceneSimulation& simulation,
                       std::span<ComplianceColumns* const> columns,
                       const std::vector<std::optional<StateSolution>>& states,
                       const std::vector<ToolState>& tools,
                       std::span<const Eigen::Vector3d> forces) {
  FrameState state;
  for (int user = 0; user < simulation.user_count(); ++user) {
    UserFrameState& out = state.users.emplace_back();
    out.tool = tools[static_cast<std::size_t>(user)];
    if (!out.tool.present) continue;
    out.force = forces[static_cast<std::size_t>(user)];
    out.pressing = simulation.pressing(user);
    out.ir = simulation.ir(user);
    out.body = simulation.body_of(user);
    if (const auto* network = std::get_if<MassSpringSimulation>(&simulation.body(out.body));
        network && out.pressing)
      out.contact_node = network->reaction(user).node;
  }
  for (int body = 0; body < simulation.body_count(); ++body) {
    const auto i = static_cast<std::size_t>(body);
    state.bodies.push_back(body_frame_state(simulation.body(body),
                                            i < columns.size() ? columns[i] : nullptr, states[i]));
  }
  return state;
}

namespace {

// The user's IR patch and, while it presses, contact nodes, as shown indices (those shown).
void add_ir_nodes(UserFrame& out, const UserFrameState& user, const ShownScene& shown) {
  if (!user.ir) return;
  const int body = user.ir->ir.object;
  if (body < 0 || static_cast<std::size_t>(body) >= shown.parts.size()) return;
  const auto add = [](google::protobuf::RepeatedField<std::uint32_t>& to, int index) {
    if (index >= 0) to.Add(static_cast<std::uint32_t>(index));
  };
  std::visit(Overloaded{[&](const CondensedFemIr& fem) {
                          const auto tag_of = [&](int node) {
                            return fem.node_ids[static_cast<std::size_t>(node)];
                          };
                          for (int node = 0; node < fem.patch_node_count; ++node)
                            add(*out.mutable_patch_nodes(), shown.of_tag(body, tag_of(node)));
                          if (user.pressing && !fem.patch.empty())
                            for (int node : fem.patch.front().nodes)
                              add(*out.mutable_contact_nodes(), shown.of_tag(body, tag_of(node)));
                        },
                        [&](const MassSpringIr& network) {
                          for (std::int32_t node : network.node_ids)
                            add(*out.mutable_patch_nodes(), shown.of_node(body, node));
                          if (user.contact_node >= 0 && user.body == body)
                            add(*out.mutable_contact_nodes(),
                                shown.of_node(body, user.contact_node));
                        },
                        [&](const HomeSpringPatch& tissue) {
                          for (int vertex : tissue.surface_vertex)
                            add(*out.mutable_patch_nodes(), shown.of_node(body, vertex));
                        },
                        [](const SeparationIr&) {}},  // separating layers have no IR nodes marked
             user.ir->ir.body);
}

}  // namespace

Frame view_frame(const FrameState& state, const ShownScene& shown, std::uint64_t sequence,
                 double time, double sim_rate_hz) {
  Frame frame;
  frame.set_sequence(sequence);
  frame.set_time(time);
  frame.set_sim_rate_hz(sim_rate_hz);
  Eigen::Matrix3Xd displacement(3, shown.node_count());
  for (std::size_t body = 0; body < state.bodies.size(); ++body) {
    const ShownPart& part = shown.parts[body];
    displacement.middleCols(part.offset, part.size()) =
        part_displacement(state.bodies[body], part, shown);
  }
  auto& u = *frame.mutable_displacement();
  u.Reserve(static_cast<int>(displacement.size()));
  for (Eigen::Index i = 0; i < displacement.size(); ++i)
    u.AddAlreadyReserved(static_cast<float>(displacement.data()[i]));
  for (std::size_t user = 0; user < state.users.size(); ++user) {
    const UserFrameState& each = state.users[user];
    UserFrame* out = frame.add_users();
    out->set_slot(static_cast<std::uint32_t>(user));
    out->set_present(each.tool.present);
    if (!each.tool.present) continue;
    add_point(*out->mutable_position(), each.tool.position);
    add_point(*out->mutable_force(), each.force);
    out->set_pressing(each.pressing);
    add_ir_nodes(*out, each, shown);
  }
  std::uint32_t boundary_nodes = 0;
  for (std::size_t body = 0; body < state.bodies.size(); ++body) {
    const auto* fem = std::get_if<ElasticFrameState>(&state.bodies[body]);
    if (!fem) continue;
    boundary_nodes += static_cast<std::uint32_t>(fem->held_nodes.size());
    for (int node : fem->held_nodes)
      if (const int index = shown.of_node(static_cast<int>(body), node); index >= 0)
        frame.add_held_nodes(static_cast<std::uint32_t>(index));
  }
  frame.set_boundary_nodes(boundary_nodes);
  for (std::size_t body = 0; body < state.bodies.size(); ++body) {
    const auto* layers = std::get_if<SeparationFrameState>(&state.bodies[body]);
    if (!layers) continue;
    InterfaceFrame* out = frame.add_interfaces();
    out->set_object(static_cast<std::uint32_t>(body));
    for (double share : layers->separated) out->add_separated(static_cast<float>(share));
    for (const GrooveSegment& segment : layers->grooves) {
      add_point(*out->mutable_grooves(), segment.a);
      add_point(*out->mutable_grooves(), segment.b);
      out->add_groove_widths(static_cast<float>(segment.width));
    }
    out->set_separated_area(layers->separated_area);
  }
  return frame;
}

}  // namespace cohaptic::view
