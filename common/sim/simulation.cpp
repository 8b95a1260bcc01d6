#include "common/sim/simulation.h"

#include <limits>

#include "common/contact/find_contact.h"
#include "common/contact/nearest_surface_nodes.h"
#include "common/util/stopwatch.h"

namespace cohaptic {

Simulation::Simulation(const Model& model, ComplianceColumns& columns, const std::vector<ToolSpec>& tools,
                       SimulationOptions options)
    : model_(model), options_(options), condensation_(columns, model.dofs) {
  users_.resize(tools.size());
  for (std::size_t u = 0; u < users_.size(); ++u) users_[u].radius = tools[u].radius;
}

void Simulation::set_tool(int user, const Eigen::Vector3d& position) {
  users_[user].known = position.allFinite();
  users_[user].position = position;
}

void Simulation::clear_tool(int user) { users_[user].known = false; }

bool Simulation::update_boundary() {
  std::vector<Eigen::Vector3d> contact_points;
  std::vector<bool> excluded(static_cast<std::size_t>(model_.mesh.node_count()), false);
  for (const UserState& user : users_) {
    if (!user.known) continue;
    for (int node : model_.surface.triangles[user.nearest]) excluded[node] = true;
    if (user.pressing) contact_points.push_back(user.position);
  }
  // A held node under a tool is released: the tool's triangle wins.
  std::vector<int> kept;
  for (int node : condensation_.boundary_nodes())
    if (!excluded[node]) kept.push_back(node);

  std::vector<int> wanted;
  if (options_.step_delay_nodes > 0 && !contact_points.empty())
    wanted = condensation_.boundary_nodes().empty()
                 ? nearest_surface_nodes(model_, contact_points, options_.step_delay_nodes, excluded)
                 : kept;
  if (wanted == condensation_.boundary_nodes()) return false;
  condensation_.set_boundary_nodes(wanted);
  // Held where they are when they join: at rest (every stroke starts from rest).
  boundary_displacement_.assign(condensation_.boundary_nodes().size(), Eigen::Vector3d::Zero());
  return true;
}

StepReport Simulation::step(double time) {
  StepReport report;
  std::vector<UserTool> tools;
  for (std::size_t u = 0; u < users_.size(); ++u) {
    UserState& user = users_[u];
    if (!user.known) {
      user.pressing = false;
      user.ir.reset();
      continue;
    }
    const ContactQuery query = find_contact(model_.mesh, model_.surface, model_.normals, model_.touchable_triangles,
                                            user.position, user.radius);
    user.pressing = query.contact.has_value();
    user.nearest = nearest_triangle(model_.mesh, model_.surface, model_.normals, model_.touchable_triangles, user.position)
                       .triangle;
    tools.push_back({static_cast<int>(u), user.position, user.radius, user.nearest});
  }
  std::vector<int> nearest;
  for (const UserState& user : users_) nearest.push_back(user.known ? user.nearest : -1);

  Stopwatch watch;
  const bool boundary_changed = update_boundary();
  if (boundary_changed || nearest != built_nearest_) {
    for (std::size_t i = 0; i < tools.size(); ++i) {
      UserState& user = users_[tools[i].user];
      IntermediateRepresentation ir =
          build_ir(model_, condensation_, tools, i, boundary_displacement_, options_.ir, ++user.epoch, time);
      report.ir_bytes += ir.size_bytes();
      user.ir = std::make_shared<const PreparedIR>(prepare_ir(std::move(ir)));
    }
    built_nearest_ = nearest;
    report.rebuilt = true;
  }
  report.rebuild_ms = watch.elapsed_ms();
  report.boundary_nodes = static_cast<int>(condensation_.boundary_nodes().size());
  return report;
}

std::vector<Eigen::Vector3d> Simulation::remote_positions(const IntermediateRepresentation& ir) const {
  std::vector<Eigen::Vector3d> positions;
  for (const IrRemoteContact& remote : ir.remotes) {
    const UserState& user = users_[remote.user];
    positions.push_back(user.known ? user.position : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  }
  return positions;
}

ForceSample Simulation::force(int user) const {
  const UserState& state = users_[user];
  if (!state.ir) return {};
  return evaluate_force(*state.ir, state.position, remote_positions(state.ir->ir));
}

}  // namespace cohaptic
