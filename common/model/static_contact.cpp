#include "common/model/static_contact.h"

#include <Eigen/LU>
#include <fmt/format.h>

#include "common/fem/static_solve.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

const Triangle& contact_triangle(const ElasticBody& body, const ContactQuery& query) {
  return body.surface.triangles[query.contact->triangle];
}

// Prescribed dofs and values for the held nodes, and (node translation) the contact nodes.
void prescribe(const ElasticBody& body, const std::vector<int>& nodes,
               const std::vector<Eigen::Vector3d>& values, std::vector<int>& dofs,
               std::vector<double>& prescribed) {
  for (std::size_t i = 0; i < nodes.size(); ++i)
    for (int axis = 0; axis < 3; ++axis)
      if (!body.dofs.is_fixed(nodes[i], axis)) {
        dofs.push_back(3 * nodes[i] + axis);
        prescribed.push_back(values[i][axis]);
      }
}

}  // namespace

std::vector<ContactQuery> find_tool_contacts(const ElasticBody& body,
                                             const std::vector<PressedTool>& tools) {
  std::vector<ContactQuery> contacts;
  std::vector<int> owner(static_cast<std::size_t>(body.mesh.node_count()), -1);
  for (std::size_t t = 0; t < tools.size(); ++t) {
    contacts.push_back(find_contact(body.mesh, body.surface, body.normals, body.touchable_triangles,
                                    tools[t].position, tools[t].radius));
    if (!contacts.back().contact) continue;
    for (int node : contact_triangle(body, contacts.back())) {
      if (owner[node] >= 0)
        throw Error(
            fmt::format("tools {} and {} press triangles that share node {}: move them apart",
                        owner[node] + 1, t + 1, body.mesh.node_tags[node]));
      owner[node] = static_cast<int>(t);
    }
  }
  return contacts;
}

std::vector<ToolReaction> contact_reactions_reference(const ElasticBody& body,
                                                      const std::vector<ContactQuery>& contacts,
                                                      const HeldNodes& held,
                                                      ContactModel contact_model,
                                                      Eigen::VectorXd* displacement) {
  std::vector<bool> is_held(static_cast<std::size_t>(body.mesh.node_count()), false);
  for (int node : held.nodes) is_held[node] = true;
  std::vector<std::size_t> pressing;
  for (std::size_t t = 0; t < contacts.size(); ++t) {
    if (!contacts[t].contact) continue;
    pressing.push_back(t);
    for (int node : contact_triangle(body, contacts[t]))
      if (is_held[node])
        throw Error(fmt::format("node {} is both held and under tool {}", body.mesh.node_tags[node],
                                t + 1));
  }

  std::vector<int> dofs;
  std::vector<double> values;
  prescribe(body, held.nodes, held.displacement, dofs, values);
  std::vector<ToolReaction> reactions(contacts.size());
  for (std::size_t t = 0; t < contacts.size(); ++t) reactions[t].query = contacts[t];

  if (contact_model == ContactModel::node_translation) {
    for (std::size_t t : pressing) {
      const Triangle& tri = contact_triangle(body, contacts[t]);
      const Eigen::Vector3d d = contacts[t].contact->displacement;
      prescribe(body, {tri.begin(), tri.end()}, {d, d, d}, dofs, values);
    }
    const StaticSolution solution = solve_static(body.stiffness, body.dofs, [&] {
      std::vector<PrescribedDisplacement> list;
      for (std::size_t i = 0; i < dofs.size(); ++i) list.push_back({dofs[i], values[i]});
      return list;
    }());
    for (std::size_t t : pressing) {
      const Triangle& tri = contact_triangle(body, contacts[t]);
      for (int i = 0; i < 3; ++i)
        for (int axis = 0; axis < 3; ++axis)
          reactions[t].nodal_forces(axis, i) =
              body.dofs.is_fixed(tri[i], axis) ? 0.0 : solution.reaction[3 * tri[i] + axis];
      reactions[t].reaction = -(reactions[t].nodal_forces * contacts[t].contact->weights);
    }
    if (displacement) *displacement = solution.displacement;
    return reactions;
  }

  // Point constraint: superpose the held-nodes case and a unit load per tool and axis.
  const ConstrainedStaticSolver solver(body.stiffness, body.dofs, dofs);
  const Eigen::VectorXd held_values =
      Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
  const StaticSolution base = solver.solve(held_values);
  const auto m = static_cast<Eigen::Index>(3 * pressing.size());
  const auto contact_point_displacement = [&](const Eigen::VectorXd& u, std::size_t t) {
    const Triangle& tri = contact_triangle(body, contacts[t]);
    const Eigen::Vector3d& w = contacts[t].contact->weights;
    return Eigen::Vector3d(w[0] * u.segment<3>(3 * tri[0]) + w[1] * u.segment<3>(3 * tri[1]) +
                           w[2] * u.segment<3>(3 * tri[2]));
  };
  std::vector<StaticSolution> unit(static_cast<std::size_t>(m));
  Eigen::MatrixXd a(m, m);
  Eigen::VectorXd rhs(m);
  for (Eigen::Index k = 0; k < m; ++k) {
    const std::size_t t = pressing[static_cast<std::size_t>(k / 3)];
    Eigen::VectorXd load = Eigen::VectorXd::Zero(3 * body.mesh.node_count());
    const Triangle& tri = contact_triangle(body, contacts[t]);
    for (int i = 0; i < 3; ++i) load[3 * tri[i] + k % 3] = contacts[t].contact->weights[i];
    unit[static_cast<std::size_t>(k)] =
        solver.solve(Eigen::VectorXd::Zero(held_values.size()), load);
    for (std::size_t j = 0; j < pressing.size(); ++j)
      a.block<3, 1>(3 * static_cast<Eigen::Index>(j), k) =
          contact_point_displacement(unit[static_cast<std::size_t>(k)].displacement, pressing[j]);
  }
  for (std::size_t j = 0; j < pressing.size(); ++j)
    rhs.segment<3>(3 * static_cast<Eigen::Index>(j)) =
        contacts[pressing[j]].contact->displacement -
        contact_point_displacement(base.displacement, pressing[j]);
  const Eigen::VectorXd lambda = a.partialPivLu().solve(rhs);
  for (std::size_t j = 0; j < pressing.size(); ++j) {
    const Eigen::Vector3d force = lambda.segment<3>(3 * static_cast<Eigen::Index>(j));
    const std::size_t t = pressing[j];
    const Triangle& tri = contact_triangle(body, contacts[t]);
    for (int i = 0; i < 3; ++i)
      for (int axis = 0; axis < 3; ++axis)
        reactions[t].nodal_forces(axis, i) =
            body.dofs.is_fixed(tri[i], axis) ? 0.0 : contacts[t].contact->weights[i] * force[axis];
    reactions[t].reaction = -force;
  }
  if (displacement) {
    *displacement = base.displacement;
    for (Eigen::Index k = 0; k < m; ++k)
      *displacement += lambda[k] * unit[static_cast<std::size_t>(k)].displacement;
  }
  return reactions;
}

}  // namespace cohaptic
