#include "common/model/static_contact.h"

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include "common/fem/static_solve.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

// The prescribed free dofs of all contact nodes, in tool-node-axis order.
struct PrescribedSet {
  std::vector<int> nodes;       ///< contact nodes, three per touching tool
  std::vector<int> dofs;        ///< free global dofs of those nodes
  std::vector<double> values;   ///< prescribed displacement per dof [m]
};

PrescribedSet prescribed_set(const Model& model, const std::vector<ContactQuery>& contacts) {
  PrescribedSet set;
  for (const ContactQuery& query : contacts) {
    if (!query.contact) continue;
    for (int node : model.surface.triangles[query.contact->triangle]) {
      set.nodes.push_back(node);
      for (int axis = 0; axis < 3; ++axis)
        if (!model.dofs.is_fixed(node, axis)) {
          set.dofs.push_back(3 * node + axis);
          set.values.push_back(query.contact->displacement[axis]);
        }
    }
  }
  return set;
}

// Tool reactions from a per-dof force lookup (global dof -> force on that dof).
template <typename ForceOfDof>
std::vector<ToolReaction> reactions_from(const Model& model, const std::vector<ContactQuery>& contacts,
                                         const ForceOfDof& force_of_dof) {
  std::vector<ToolReaction> reactions(contacts.size());
  for (std::size_t t = 0; t < contacts.size(); ++t) {
    reactions[t].query = contacts[t];
    if (!contacts[t].contact) continue;
    const ToolContact& contact = *contacts[t].contact;
    const Triangle& tri = model.surface.triangles[contact.triangle];
    for (int i = 0; i < 3; ++i)
      for (int axis = 0; axis < 3; ++axis)
        reactions[t].nodal_forces(axis, i) = model.dofs.is_fixed(tri[i], axis) ? 0.0 : force_of_dof(3 * tri[i] + axis);
    reactions[t].reaction = -(reactions[t].nodal_forces * contact.weights);
  }
  return reactions;
}

}  // namespace

std::vector<ContactQuery> find_tool_contacts(const Model& model, const std::vector<PressedTool>& tools) {
  std::vector<ContactQuery> contacts;
  std::vector<int> owner(static_cast<std::size_t>(model.mesh.node_count()), -1);
  for (std::size_t t = 0; t < tools.size(); ++t) {
    contacts.push_back(find_contact(model.mesh, model.surface, model.normals, model.touchable_triangles,
                                    tools[t].position, tools[t].radius));
    if (!contacts.back().contact) continue;
    for (int node : model.surface.triangles[contacts.back().contact->triangle]) {
      if (owner[node] >= 0)
        throw Error(fmt::format("tools {} and {} press triangles that share node {}: move them apart", owner[node] + 1,
                                t + 1, model.mesh.node_tags[node]));
      owner[node] = static_cast<int>(t);
    }
  }
  return contacts;
}

std::vector<ToolReaction> contact_reactions_condensed(const Model& model, ComplianceColumns& columns,
                                                      const std::vector<ContactQuery>& contacts) {
  const PrescribedSet set = prescribed_set(model, contacts);
  Eigen::VectorXd force_by_dof = Eigen::VectorXd::Zero(3 * model.mesh.node_count());
  if (!set.dofs.empty()) {
    // L_AA over the free dofs of the contact nodes.
    const Eigen::MatrixXd l_nodes = columns.gather(set.nodes);
    std::vector<int> local;  // position of each prescribed dof inside l_nodes
    for (int dof : set.dofs) {
      const auto it = std::find(set.nodes.begin(), set.nodes.end(), dof / 3);
      local.push_back(3 * static_cast<int>(it - set.nodes.begin()) + dof % 3);
    }
    const auto m = static_cast<Eigen::Index>(local.size());
    Eigen::MatrixXd l_aa(m, m);
    for (Eigen::Index i = 0; i < m; ++i)
      for (Eigen::Index j = 0; j < m; ++j) l_aa(i, j) = l_nodes(local[i], local[j]);
    const Eigen::LLT<Eigen::MatrixXd> llt(l_aa);
    if (llt.info() != Eigen::Success)
      throw NumericalError(fmt::format("the condensed compliance of {} contact dofs is not positive definite", m));
    const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(set.values.data(), m);
    const Eigen::VectorXd f = llt.solve(u);
    for (Eigen::Index i = 0; i < m; ++i) force_by_dof[set.dofs[i]] = f[i];
  }
  return reactions_from(model, contacts, [&](int dof) { return force_by_dof[dof]; });
}

std::vector<ToolReaction> contact_reactions_reference(const Model& model, const std::vector<ContactQuery>& contacts,
                                                      Eigen::VectorXd* displacement) {
  const PrescribedSet set = prescribed_set(model, contacts);
  std::vector<PrescribedDisplacement> prescribed;
  for (std::size_t i = 0; i < set.dofs.size(); ++i) prescribed.push_back({set.dofs[i], set.values[i]});
  const StaticSolution solution = solve_static(model.stiffness, model.dofs, prescribed);
  if (displacement) *displacement = solution.displacement;
  return reactions_from(model, contacts, [&](int dof) { return solution.reaction[dof]; });
}

Eigen::VectorXd displacement_under_reactions(const Model& model, const std::vector<ToolReaction>& reactions) {
  Eigen::VectorXd free_forces = Eigen::VectorXd::Zero(model.dofs.free_count());
  for (const ToolReaction& r : reactions) {
    if (!r.query.contact) continue;
    const Triangle& tri = model.surface.triangles[r.query.contact->triangle];
    for (int i = 0; i < 3; ++i)
      for (int axis = 0; axis < 3; ++axis) {
        const int free = model.dofs.free_index[3 * tri[i] + axis];
        if (free >= 0) free_forces[free] += r.nodal_forces(axis, i);
      }
  }
  const Eigen::VectorXd free_u = model.free_factor->solve(free_forces);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * model.mesh.node_count());
  for (int i = 0; i < model.dofs.free_count(); ++i) u[model.dofs.free_dofs[i]] = free_u[i];
  return u;
}

}  // namespace cohaptic
