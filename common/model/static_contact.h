// The reference answer for tools pressed into a model: full sparse static solves.
//
// Each pressing tool's contact triangle is found (find_contact.h); boundary nodes B are
// held at given displacements; every other free node carries no external force.
//   node translation: the triangle's three nodes are prescribed d; the force on the tool is
//     -sum_i w_i f_i (the paper's eq. 5), f_i the reactions at those nodes;
//   point constraint: the contact point w . u of the triangle follows d with the least
//     energy; the tool force lambda is applied at the nodes as w_i lambda. One
//     factorisation, 1 + 3 m load cases for m pressing tools, a 3m x 3m system.
// A fixed axis of a contact node is held by its support: it carries no tool force.
// This is deliberately the slow path (a CHOLMOD factorisation per call) that the
// condensed IR is checked against. Units: m, N.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "common/contact/find_contact.h"
#include "common/model/elastic_body.h"

namespace cohaptic {

struct PressedTool {
  Eigen::Vector3d position;  ///< point or sphere centre [m]
  double radius = 0;         ///< [m], 0 for a point
};

/// Boundary nodes held at given displacements (the set B with u_B).
struct HeldNodes {
  std::vector<int> nodes;
  std::vector<Eigen::Vector3d> displacement;  ///< [m], per node
};

struct ToolReaction {
  ContactQuery query;  ///< contact empty: the tool touches nothing
  Eigen::Matrix3d nodal_forces =
      Eigen::Matrix3d::Zero();  ///< column i: tool force on contact node i [N]
  Eigen::Vector3d reaction = Eigen::Vector3d::Zero();  ///< force on the tool [N]
};

/// Finds every tool's contact. Throws Error if two tools press triangles sharing a node
/// (one node cannot follow two tools).
std::vector<ContactQuery> find_tool_contacts(const ElasticBody& body,
                                             const std::vector<PressedTool>& tools);

/// Full sparse solve; also returns the displacement field (3N) if asked. Throws Error if a
/// held node is also a contact node.
std::vector<ToolReaction> contact_reactions_reference(const ElasticBody& body,
                                                      const std::vector<ContactQuery>& contacts,
                                                      const HeldNodes& held,
                                                      ContactModel contact_model,
                                                      Eigen::VectorXd* displacement = nullptr);

}  // namespace cohaptic
