#include "common/model/contact_reference.h"

#include "common/fem/static_solve.h"

namespace cohaptic {

ContactReference::ContactReference(const ElasticBody& body) : body_(body) {}

const ContactReference::ContactSet& ContactReference::contact_set(
    const std::vector<ContactQuery>& contacts) {
  std::vector<int> key;
  for (const ContactQuery& query : contacts)
    key.push_back(query.contact ? query.contact->triangle : -1);
  if (const auto found = sets_.find(key); found != sets_.end()) return found->second;

  ContactSet set;
  std::vector<int> prescribed;                     // free dofs of the pressing triangles' nodes
  std::vector<std::pair<std::size_t, int>> owner;  // per prescribed dof: (pressing index, axis)
  for (std::size_t t = 0; t < contacts.size(); ++t) {
    if (!contacts[t].contact) continue;
    for (int node : body_.surface.triangles[contacts[t].contact->triangle])
      for (int axis = 0; axis < 3; ++axis)
        if (!body_.dofs.is_fixed(node, axis)) {
          prescribed.push_back(3 * node + axis);
          owner.emplace_back(set.pressing.size(), axis);
        }
    set.pressing.push_back(t);
  }
  const auto m = static_cast<Eigen::Index>(set.pressing.size());
  set.nodal_per_displacement = Eigen::MatrixXd::Zero(9 * m, 3 * m);
  if (m > 0) {
    ++factorisations_;
    const ConstrainedStaticSolver solver(body_.stiffness, body_.dofs, prescribed);
    for (Eigen::Index unit = 0; unit < 3 * m; ++unit) {
      Eigen::VectorXd values(static_cast<Eigen::Index>(prescribed.size()));
      for (std::size_t i = 0; i < prescribed.size(); ++i)
        values[static_cast<Eigen::Index>(i)] =
            static_cast<Eigen::Index>(owner[i].first) == unit / 3 && owner[i].second == unit % 3
                ? 1.0
                : 0.0;
      const StaticSolution solution = solver.solve(values);
      for (Eigen::Index p = 0; p < m; ++p) {
        const Triangle& tri = body_.surface.triangles[contacts[set.pressing[p]].contact->triangle];
        for (int i = 0; i < 3; ++i)
          for (int axis = 0; axis < 3; ++axis)
            if (!body_.dofs.is_fixed(tri[i], axis))
              set.nodal_per_displacement(9 * p + 3 * i + axis, unit) =
                  solution.reaction[3 * tri[i] + axis];
      }
    }
  }
  return sets_.emplace(std::move(key), std::move(set)).first->second;
}

std::vector<Eigen::Vector3d> ContactReference::forces_with_held(
    const std::vector<ContactQuery>& contacts, const HeldNodes& held) {
  std::vector<int> key;
  for (const ContactQuery& query : contacts)
    key.push_back(query.contact ? query.contact->triangle : -1);
  key.push_back(-2);  // between the triangles and the held nodes
  key.insert(key.end(), held.nodes.begin(), held.nodes.end());
  std::vector<std::pair<int, double>> values;  // (prescribed dof, value), in solver order
  for (const ContactQuery& query : contacts) {
    if (!query.contact) continue;
    for (int node : body_.surface.triangles[query.contact->triangle])
      for (int axis = 0; axis < 3; ++axis)
        if (!body_.dofs.is_fixed(node, axis))
          values.emplace_back(3 * node + axis, query.contact->displacement[axis]);
  }
  std::vector<bool> under_tool(static_cast<std::size_t>(body_.mesh.node_count()), false);
  for (const ContactQuery& query : contacts)
    if (query.contact)
      for (int node : body_.surface.triangles[query.contact->triangle]) under_tool[node] = true;
  for (std::size_t h = 0; h < held.nodes.size(); ++h) {
    if (under_tool[held.nodes[h]]) continue;  // the tool wins, as in the simulation
    for (int axis = 0; axis < 3; ++axis)
      if (!body_.dofs.is_fixed(held.nodes[h], axis))
        values.emplace_back(3 * held.nodes[h] + axis, held.displacement[h][axis]);
  }
  if (!held_solver_ || key != held_key_) {
    std::vector<int> prescribed;
    for (const auto& [dof, value] : values) prescribed.push_back(dof);
    held_solver_ = std::make_unique<ConstrainedStaticSolver>(body_.stiffness, body_.dofs,
                                                             std::move(prescribed));
    held_key_ = std::move(key);
    ++factorisations_;
  }
  Eigen::VectorXd prescribed(static_cast<Eigen::Index>(values.size()));
  for (std::size_t i = 0; i < values.size(); ++i)
    prescribed[static_cast<Eigen::Index>(i)] = values[i].second;
  const StaticSolution solution = held_solver_->solve(prescribed);
  std::vector<Eigen::Vector3d> out(contacts.size(), Eigen::Vector3d::Zero());
  for (std::size_t t = 0; t < contacts.size(); ++t) {
    if (!contacts[t].contact) continue;
    const Triangle& tri = body_.surface.triangles[contacts[t].contact->triangle];
    for (int i = 0; i < 3; ++i)
      for (int axis = 0; axis < 3; ++axis)
        if (!body_.dofs.is_fixed(tri[i], axis))
          out[t][axis] -= contacts[t].contact->weights[i] * solution.reaction[3 * tri[i] + axis];
  }
  return out;
}

std::vector<Eigen::Vector3d> ContactReference::forces(const std::vector<PressedTool>& tools,
                                                      const HeldNodes& held) {
  const std::vector<ContactQuery> contacts = find_tool_contacts(body_, tools);
  if (!held.nodes.empty()) return forces_with_held(contacts, held);
  const ContactSet& set = contact_set(contacts);
  const auto m = static_cast<Eigen::Index>(set.pressing.size());
  Eigen::VectorXd displacement(3 * m);
  for (Eigen::Index p = 0; p < m; ++p)
    displacement.segment<3>(3 * p) = contacts[set.pressing[p]].contact->displacement;
  const Eigen::VectorXd nodal = set.nodal_per_displacement * displacement;
  std::vector<Eigen::Vector3d> out(tools.size(), Eigen::Vector3d::Zero());
  for (Eigen::Index p = 0; p < m; ++p) {
    const Eigen::Vector3d& w = contacts[set.pressing[p]].contact->weights;
    for (int i = 0; i < 3; ++i) out[set.pressing[p]] -= w[i] * nodal.segment<3>(9 * p + 3 * i);
  }
  return out;
}

}  // namespace cohaptic
