#include "common/sim/fem_pair_interaction.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>
#include <memory>

#include "common/interaction/interaction_step.h"

namespace cohaptic {
namespace {

// The loads in `by_dof` (global dof -> force), free dofs only, as AppliedLoads.
AppliedLoads fem_pair_applied_loads(const std::map<int, double>& by_dof, const DofMap& dofs) {
  AppliedLoads loads;
  std::vector<double> forces;
  for (const auto& [dof, force] : by_dof)
    if (!dofs.is_fixed(dof / 3, dof % 3)) {
      loads.dofs.push_back(dof);
      forces.push_back(force);
    }
  loads.forces =
      Eigen::Map<const Eigen::VectorXd>(forces.data(), static_cast<Eigen::Index>(forces.size()));
  return loads;
}

// A's node positions with its surface nodes at `state`'s displacement (the rest elsewhere:
// only surface nodes can meet B).
Eigen::Matrix3Xd fem_pair_front_positions(const ElasticBody& body, ComplianceColumns& columns,
                                          const StateSolution& state) {
  Eigen::Matrix3Xd positions = body.mesh.nodes;
  const Eigen::Matrix3Xd u = displacement_of_nodes(columns, state, body.surface.nodes);
  for (std::size_t i = 0; i < body.surface.nodes.size(); ++i)
    positions.col(body.surface.nodes[i]) += u.col(static_cast<Eigen::Index>(i));
  return positions;
}

}  // namespace

FemPairInteraction make_fem_pair_interaction(int front, const ElasticBody& front_body, int behind,
                                             const ElasticBody& behind_body) {
  FemPairInteraction interaction;
  interaction.front = front;
  interaction.behind = behind;
  interaction.front_surface =
      make_surface_adjacency(front_body.surface.triangles, front_body.mesh.node_count());
  interaction.behind_surface =
      make_surface_adjacency(behind_body.surface.triangles, behind_body.mesh.node_count());
  interaction.pairs = make_node_pairs(front_body.surface.nodes, front_body.mesh.nodes,
                                      behind_body.surface.nodes, behind_body.mesh.nodes);
  return interaction;
}

FemPairLoads step_fem_pair(FemPairInteraction& interaction, const ElasticBody& front_body,
                           ComplianceColumns& front_columns, const StateSolution& front_alone,
                           const ElasticBody& behind_body, ComplianceColumns& behind_columns) {
  const Eigen::Matrix3Xd positions =
      fem_pair_front_positions(front_body, front_columns, front_alone);
  const InteractingBodies bodies{positions,
                                 interaction.front_surface,
                                 behind_body.mesh.nodes,
                                 interaction.behind_surface,
                                 behind_body.dofs,
                                 behind_columns};
  interaction.collisions = keep_pairs_and_find_within(interaction.pairs, bodies, kFemPairReach);
  interaction.contact = {};
  FemPairLoads loads;
  if (interaction.collisions.empty()) return loads;

  std::vector<int> held = front_alone.contact_dofs;  // the tools' triangles stay where they are ...
  held.insert(held.end(), front_alone.boundary_dofs.begin(),
              front_alone.boundary_dofs.end());  // ... as do held nodes
  interaction.contact =
      solve_fem_pair_contact(interaction.collisions, front_columns, held, behind_columns);
  if (!interaction.contact.solved) {
    // Neither body gives way along some normal (e.g. a held node of A on a fixed part of B):
    // no push this step rather than an unbounded one.
    if (interaction.failures++ == 0)
      spdlog::warn(
          "FEM pair (objects {} and {}): the coupled contact is not positive definite; no push "
          "this step "
          "(counted, logged once)",
          interaction.front, interaction.behind);
    interaction.contact.pushes.setZero();
    return loads;
  }

  std::map<int, double> on_front, on_behind;
  std::vector<Eigen::Index> pushing;
  for (std::size_t j = 0; j < interaction.collisions.size(); ++j) {
    const double push = interaction.contact.pushes[static_cast<Eigen::Index>(j)];
    if (push <= 0) continue;
    const PolygonCollision& collision = interaction.collisions[j];
    pushing.push_back(static_cast<Eigen::Index>(j));
    for (int axis = 0; axis < 3; ++axis) {
      on_front[3 * collision.active + axis] += push * collision.normal[axis];
      for (int k = 0; k < 3; ++k)
        on_behind[3 * collision.polygon[static_cast<std::size_t>(k)] + axis] -=
            collision.weights[k] * push * collision.normal[axis];
    }
  }
  loads.front = fem_pair_applied_loads(on_front, front_body.dofs);
  loads.behind = fem_pair_applied_loads(on_behind, behind_body.dofs);
  const auto count = static_cast<Eigen::Index>(pushing.size());
  loads.support_normals.resize(3, count);
  loads.support_compliance.resize(count, count);
  loads.support_gaps.resize(count);
  for (Eigen::Index a = 0; a < count; ++a) {
    const PolygonCollision& collision =
        interaction.collisions[static_cast<std::size_t>(pushing[static_cast<std::size_t>(a)])];
    loads.support_nodes.push_back(collision.active);
    loads.support_normals.col(a) = collision.normal;
    loads.support_gaps[a] =
        (front_body.mesh.nodes.col(collision.active) - collision.target).dot(collision.normal);
    for (Eigen::Index b = 0; b < count; ++b)
      loads.support_compliance(a, b) = interaction.contact.behind_compliance(
          pushing[static_cast<std::size_t>(a)], pushing[static_cast<std::size_t>(b)]);
  }
  return loads;
}

void couple_fem_pair(FemPairInteraction& interaction, Simulation& front,
                     const ElasticBody& front_body, ComplianceColumns& front_columns,
                     Simulation& behind, const ElasticBody& behind_body,
                     ComplianceColumns& behind_columns) {
  FemPairLoads loads = step_fem_pair(interaction, front_body, front_columns, front.solve_unloaded(),
                                     behind_body, behind_columns);
  front.set_applied_loads(std::move(loads.front));
  behind.set_applied_loads(std::move(loads.behind));
  // The IRs' support changes with the set S only (like an active set); within a set the
  // targets B had when it formed stand.
  std::vector<int> current =
      front.support() ? front.support()->support_nodes() : std::vector<int>{};
  std::vector<int> next = loads.support_nodes;
  std::sort(current.begin(), current.end());
  std::sort(next.begin(), next.end());
  if (next == current) return;
  front.set_support(loads.support_nodes.empty()
                        ? nullptr
                        : std::make_unique<SupportedCompliance>(
                              front_columns, front_body.dofs, loads.support_nodes,
                              loads.support_normals, loads.support_compliance, loads.support_gaps));
}

}  // namespace cohaptic
