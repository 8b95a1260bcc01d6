#include "view/view_messages.h"

#include <Eigen/Geometry>

namespace cohaptic::view {
namespace {

void add_point(google::protobuf::RepeatedField<float>& out, const Eigen::Vector3d& p) {
  for (int axis = 0; axis < 3; ++axis) out.Add(static_cast<float>(p[axis]));
}

// A plane obstacle as a square around the object's projection on it, twice the object's size.
void add_plane(Obstacle& out, const Eigen::Vector3d& point, const Eigen::Vector3d& normal, const Eigen::Matrix3Xd& nodes) {
  const Eigen::Vector3d centre = nodes.rowwise().mean();
  const Eigen::Vector3d on_plane = centre - normal.dot(centre - point) * normal;
  const double half = (nodes.rowwise().maxCoeff() - nodes.rowwise().minCoeff()).norm();
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  for (const auto& [a, b] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}})
    add_point(*out.mutable_vertices(), on_plane + half * (a * u + b * v));
  for (std::uint32_t index : {0u, 1u, 2u, 0u, 2u, 3u}) out.add_triangles(index);
}

}  // namespace

Scene view_scene(const Model& model, const ElasticBody& body, const ShownSurface& shown, wire::Protocol protocol, const record::InjectedDelays& injected,
                 double frame_rate_hz, const std::string& source) {
  Scene scene;
  scene.set_scene_name(model.scene.name);
  scene.set_units(model.scene.units);
  scene.set_metres_per_unit(model.scene.metres_per_unit);
  for (int node : shown.nodes) add_point(*scene.mutable_rest_positions(), body.mesh.nodes.col(node));
  for (const Triangle& tri : shown.triangles)
    for (int corner : tri) scene.add_triangles(static_cast<std::uint32_t>(corner));
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
      add_plane(*out, obstacle.plane->first, obstacle.plane->second, body.mesh.nodes);
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

ShownIndex::ShownIndex(const ElasticBody& body, const ShownSurface& shown) : shown_(shown) {
  for (int node : shown.nodes) node_of_tag_[body.mesh.node_tags[static_cast<std::size_t>(node)]] = node;
}

int ShownIndex::of_tag(std::int64_t tag) const {
  const auto found = node_of_tag_.find(tag);
  return found == node_of_tag_.end() ? -1 : of_node(found->second);
}

FrameState frame_state(const Simulation& simulation, std::vector<LoadedColumn> loads, const std::vector<ToolState>& tools) {
  FrameState state;
  for (int user = 0; user < simulation.user_count(); ++user) {
    UserFrameState& out = state.users.emplace_back();
    out.tool = tools[static_cast<std::size_t>(user)];
    if (!out.tool.present) continue;
    out.force = simulation.force(user).force;
    out.pressing = simulation.pressing(user);
    out.ir = simulation.ir(user);
  }
  state.held_nodes = simulation.condensation().boundary_nodes();
  state.loads = std::move(loads);
  return state;
}

Frame view_frame(const FrameState& state, const ShownIndex& index, std::span<const int> row_positions,
                 std::uint64_t sequence, double time, double sim_rate_hz) {
  Frame frame;
  frame.set_sequence(sequence);
  frame.set_time(time);
  frame.set_sim_rate_hz(sim_rate_hz);
  const Eigen::Matrix3Xd displacement = displacement_of_rows(state.loads, row_positions);
  auto& u = *frame.mutable_displacement();
  u.Reserve(static_cast<int>(displacement.size()));
  for (Eigen::Index i = 0; i < displacement.size(); ++i) u.AddAlreadyReserved(static_cast<float>(displacement.data()[i]));
  const auto add_tagged = [&](google::protobuf::RepeatedField<std::uint32_t>& out, std::int64_t tag) {
    if (const int shown = index.of_tag(tag); shown >= 0) out.Add(static_cast<std::uint32_t>(shown));
  };
  for (std::size_t user = 0; user < state.users.size(); ++user) {
    const UserFrameState& each = state.users[user];
    UserFrame* out = frame.add_users();
    out->set_slot(static_cast<std::uint32_t>(user));
    out->set_present(each.tool.present);
    if (!each.tool.present) continue;
    add_point(*out->mutable_position(), each.tool.position);
    add_point(*out->mutable_force(), each.force);
    out->set_pressing(each.pressing);
    const CondensedFemIr* fem = each.ir ? std::get_if<CondensedFemIr>(&each.ir->ir.body) : nullptr;
    if (!fem) continue;
    for (int node = 0; node < fem->patch_node_count; ++node)
      add_tagged(*out->mutable_patch_nodes(), fem->node_ids[static_cast<std::size_t>(node)]);
    if (each.pressing && !fem->patch.empty())
      for (int node : fem->patch.front().nodes) add_tagged(*out->mutable_contact_nodes(), fem->node_ids[static_cast<std::size_t>(node)]);
  }
  frame.set_boundary_nodes(static_cast<std::uint32_t>(state.held_nodes.size()));
  for (int node : state.held_nodes)
    if (const int shown = index.of_node(node); shown >= 0) frame.add_held_nodes(static_cast<std::uint32_t>(shown));
  return frame;
}

}  // namespace cohaptic::view
