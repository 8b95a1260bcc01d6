// The two bodies condensed onto their common surface, and the stiffness a rigid tool
// footprint on the pulled body's interface face meets for any set of tied node pairs.
//
// Each body's compliance at its interface nodes, L1 (pulled) and L2 (base), comes from one
// CHOLMOD factorisation of its K_ff and 3 solves per interface node (ComplianceColumns).
// A tied pair carries equal and opposite interface forces lambda that make its two nodes
// move together; with the tool's force f on the pulled body's dofs,
//   u1 = L1 (f + E_T lambda),  u2 = -L2 E_T lambda,  E_T^T (u1 - u2) = 0,
// so the pulled body's compliance with the pairs T tied is L1 - L1_:T G_T^-1 L1_T:, with
// G_T = (L1 + L2)_TT. H = (L1 + L2)^-1 and H L1 are formed once; releasing a few pairs R
// is the block downdate G_T^-1 = H_TT - H_TR H_RR^-1 H_RT, so each footprint's three
// states cost O(n), not a factorisation. This is exactly the full sparse solve of the two meshes
// with tied pairs merged (the tests compare both). Units: m/N, N/m.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/separation/separation_bodies.h"

namespace cohaptic {

struct InterfaceCompliance {
  Eigen::MatrixXd pulled;  ///< L1: 3n x 3n [m/N], interface node order, axes x y z
  Eigen::MatrixXd base;    ///< L2
  double seconds = 0;      ///< both factorisations and all columns
};

/// Throws Error if an interface node of the pulled body is supported (the fields need it
/// free), NumericalError (naming the body) if a body's supports leave it a rigid motion.
InterfaceCompliance interface_compliance(const SeparationBodies& bodies,
                                         const SeparationInterface& interface);

class TiedInterface {
 public:
  /// Forms H; `compliance` must outlive this object.
  explicit TiedInterface(const InterfaceCompliance& compliance);

  int node_count() const { return static_cast<int>(h_.rows() / 3); }

  /// Compliances (3|F| x 3|F|) of the pulled body's interface nodes `footprint`.
  struct FootprintCompliances {
    Eigen::MatrixXd connected;          ///< every pair tied
    Eigen::MatrixXd locally_separated;  ///< every pair tied but `released`
    Eigen::MatrixXd separated;          ///< no pair tied
  };
  FootprintCompliances footprint_compliances(std::span<const int> footprint,
                                             std::span<const int> released) const;

 private:
  const Eigen::MatrixXd& l1_;
  Eigen::MatrixXd h_;     ///< (L1 + L2)^-1
  Eigen::MatrixXd h_l1_;  ///< H L1
};

/// The force-deflection stiffness of a rigid footprint: every node of it displaced by the
/// same delta, the rest of the interface unloaded; K = E^T C^-1 E, E = (I I ... I)^T.
Eigen::Matrix3d rigid_footprint_stiffness(const Eigen::MatrixXd& footprint_compliance);

}  // namespace cohaptic
