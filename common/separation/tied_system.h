// The two bodies as one sparse FEM system with the tied pairs merged into one node: the
// direct way to the force a tool feels for a given state of connection. It is what the
// precomputed fields are checked against (a full sparse solve per deflection, no
// condensation) and the naive method the haptic evaluation is benchmarked against (a
// factorisation and solve per tick). Units: m, N, N/m.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/fem/assemble_stiffness.h"
#include "common/fem/dof_map.h"
#include "common/separation/separation_bodies.h"

namespace cohaptic {

struct TiedSystem {
  SparseMatrix stiffness;             ///< both bodies, merged numbering
  DofMap dofs;                        ///< both bodies' supports
  std::vector<int> pulled_to_merged;  ///< per node of the pulled body
};

/// `tied` per interface node: whether its pair is one node.
TiedSystem tied_system(const SeparationBodies& bodies, const SeparationInterface& interface,
                       const std::vector<bool>& tied);

/// The forces a rigid footprint (interface nodes of the pulled body, all displaced by one
/// of `deltas`, every other free node unloaded) applies to the bodies: one factorisation
/// for the footprint, one full sparse solve per deflection.
std::vector<Eigen::Vector3d> footprint_forces(const TiedSystem& system,
                                              const SeparationInterface& interface,
                                              std::span<const int> footprint,
                                              std::span<const Eigen::Vector3d> deltas);

}  // namespace cohaptic
