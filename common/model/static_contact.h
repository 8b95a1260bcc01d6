// Static reaction forces of tools pressed into a model at rest (node translation).
//
// Each pressing tool's contact triangle is found (find_contact.h); its three nodes are
// prescribed the displacement d, every other free node carries no external force. The
// nodal forces f_A then follow either by condensation on the compliance,
// f_A = L_AA^-1 u_A (the paper's eq. 3 with no boundary nodes), or by the full sparse
// solve (the reference path). The force the tool feels is -sum_i w_i f_i (eq. 5).
// A fixed axis of a contact node is held by its support: it is not prescribed and carries
// no tool force. Units: m, N.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "common/contact/find_contact.h"
#include "common/fem/compliance.h"
#include "common/model/model.h"

namespace cohaptic {

struct PressedTool {
  Eigen::Vector3d position;  ///< point or sphere centre [m]
  double radius = 0;         ///< [m], 0 for a point
};

struct ToolReaction {
  ContactQuery query;                                    ///< contact empty: the tool touches nothing
  Eigen::Matrix3d nodal_forces = Eigen::Matrix3d::Zero();  ///< column i: tool force on contact node i [N]
  Eigen::Vector3d reaction = Eigen::Vector3d::Zero();      ///< force on the tool [N]
};

/// Finds every tool's contact. Throws Error if two tools press triangles sharing a node
/// (one node cannot follow two tools under node translation).
std::vector<ContactQuery> find_tool_contacts(const Model& model, const std::vector<PressedTool>& tools);

/// By condensation on compliance columns (computed on demand where missing).
std::vector<ToolReaction> contact_reactions_condensed(const Model& model, ComplianceColumns& columns,
                                                      const std::vector<ContactQuery>& contacts);

/// By the full sparse solve; also returns the displacement field (3N) if asked.
std::vector<ToolReaction> contact_reactions_reference(const Model& model, const std::vector<ContactQuery>& contacts,
                                                      Eigen::VectorXd* displacement = nullptr);

/// Displacement field (3N) of the body under the tools' nodal forces: one solve with K_ff.
Eigen::VectorXd displacement_under_reactions(const Model& model, const std::vector<ToolReaction>& reactions);

}  // namespace cohaptic
