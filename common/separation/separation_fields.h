// The precomputed force-deflection fields of the separation-forces paper (Sec. V.C,
// Algorithm V.1), fitted to our own linear FEM.
//
// For interface node i of the pulled body and tool node j (a rigid footprint: every
// interface node within the tool node's radius of node i moves with the tool), three
// fields: F (every pair tied), F-bar (the triangles of D_i released) and F^e (no pair
// tied). Each is stored in a frame of its own (the paper's 9 frame numbers): the
// principal axes of that state's symmetric stiffness, z the one nearest the interface
// normal (pointing into the pulled body), x the one nearest the global x axis. Along each
// frame axis a a polynomial through the origin of the deflection component along a,
//   F(delta) = R f(R^T delta),   f_a(s) = c_a1 s + ... + c_ad s^d,
// is fitted by least squares to the FEM force at `samples_per_axis` deflections in
// [-max_deflection, max_deflection]. The field is the gradient of sum_a int_0 f_a: it
// does no net work round a closed path. Linear FEM is diagonal in the principal frame, so
// the fit is exact for every degree (the higher coefficients are round-off).
//
// F is the force the tool applies to the pulled body (N); the hand feels -F.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "common/separation/separation_bodies.h"

namespace cohaptic {

enum class FieldState : int { connected = 0, locally_separated = 1, separated = 2 };
constexpr int kFieldStates = 3;

const char* field_state_name(FieldState state);

struct FieldSettings {
  int degree = 3;                            ///< the paper used 3 and proposes 5
  int samples_per_axis = 6;                  ///< non-zero ones (an odd count has a zero) >= degree
  double max_deflection = 0.005;             ///< half range of the sampled deflections [m]
  std::vector<double> footprint_radii{0.0};  ///< per tool node [m]; 0: the node alone
};

/// Throws Error naming the bad setting.
void validate(const FieldSettings& settings);

struct SeparationFields {
  int degree = 0;
  int node_count = 0;
  int tool_node_count = 0;
  /// [node][tool node][state] blocks of block_size(degree) doubles: the frame R (3 x 3,
  /// column-major: columns are the frame's x, y, z in the interface's coordinates), then
  /// c_a1..c_ad for a = x, y, z.
  std::vector<double> values;

  static constexpr int block_size(int degree) { return 9 + 3 * degree; }
  std::span<const double> block(int node, int tool_node, FieldState state) const;
  std::span<double> block(int node, int tool_node, FieldState state);
};

struct FieldPrecomputeReport {
  double compliance_seconds = 0;  ///< both CHOLMOD factorisations and the interface columns
  double tie_seconds = 0;         ///< forming (L1 + L2)^-1
  double stiffness_seconds = 0;   ///< every field's condensed stiffness (the three states together)
  double fit_seconds = 0;         ///< frames, samples and fits of every field
  /// Per state: max over fields and samples of |F_fit - F_fem| / max over the field's samples
  /// |F_fem|.
  std::array<double, kFieldStates> max_fit_error{};
  int field_count = 0;  ///< nodes x tool nodes x 3
  double total_seconds() const {
    return compliance_seconds + tie_seconds + stiffness_seconds + fit_seconds;
  }
};

/// The FEM force for one field at deflection `delta`: K delta, K the stiffness the rigid
/// footprint of (node, tool node) meets in `state` (what the fit is fitted to).
struct FieldStiffnesses {
  std::vector<std::array<Eigen::Matrix3d, kFieldStates>>
      stiffness;  ///< [node * tool_nodes + tool node]
};

/// Condenses both bodies onto the interface (CHOLMOD), forms every field's stiffness.
FieldStiffnesses field_stiffnesses(const SeparationBodies& bodies,
                                   const SeparationInterface& interface,
                                   const FieldSettings& settings,
                                   FieldPrecomputeReport* report = nullptr);

/// Frames, samples and fits for every field (Algorithm V.1).
SeparationFields precompute_separation_fields(const SeparationBodies& bodies,
                                              const SeparationInterface& interface,
                                              const FieldSettings& settings,
                                              FieldPrecomputeReport* report = nullptr);

/// Interface nodes within `radius` of `node` (the node itself first).
std::vector<int> tool_footprint(const SeparationInterface& interface, int node, double radius);

}  // namespace cohaptic
