// SeparationPatch: the compact, immutable description of a separating interface that the
// haptic-rate evaluation runs on, on the server (P0) and on the client (P1) alike — what
// the intermediate representation carries for a separation body.
//
// Per interface node: rest position, its region D_n (the interface triangles around it)
// and |D_n|, and per tool node the three fitted fields F, F-bar, F^e (frame and
// coefficients, see separation_fields.h). Per triangle: nodes, edge neighbours, which rim
// edges may start a crack, unit normal (into the pulled body), centroid and area. Scalars:
// |C| the whole interface's area (the patch may be a part of it), J_c, l_n, l_t and the
// thresholds F_n = J_c l_n, F_t = J_c l_t, the friction coefficient, the laser's absorbed
// power alpha P, spot l_f, reach and vaporisation speed v_s, and the force limit.
// Everything is flat (vectors sized once) so the evaluation allocates nothing.
// Units: m, m^2, N, J/m^2, W, m/s.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "common/separation/interface_regions.h"
#include "common/separation/separation_bodies.h"
#include "common/separation/separation_fields.h"
#include "common/separation/separation_settings.h"

namespace cohaptic {

struct SeparationPatch {
  /// The largest region D_n the evaluation's fixed working storage holds.
  static constexpr int kMaxRegionTriangles = 24;

  Eigen::Matrix3Xd positions;                  ///< per node, at rest [m]
  std::vector<Triangle> triangles;             ///< node indices, normal into the pulled body
  std::vector<std::array<int, 3>> neighbours;  ///< triangle across edge (k, k+1), or -1
  std::vector<std::uint8_t> open_rim;          ///< bit k: rim edge (k, k+1) may start a crack
  std::vector<Eigen::Vector3d> normals;        ///< per triangle, unit
  std::vector<Eigen::Vector3d> centroids;      ///< per triangle [m]
  std::vector<double> areas;                   ///< per triangle [m^2]
  NodeRegions regions;                         ///< D_n per node
  std::vector<double> region_areas;            ///< |D_n| [m^2]
  double interface_area = 0;                   ///< |C| [m^2]

  int degree = 0;
  int tool_node_count = 0;
  std::vector<double> fields;  ///< as SeparationFields::values

  double toughness = 0;             ///< J_c [J/m^2]
  double normal_length = 0;         ///< l_n [m]
  double tangential_length = 0;     ///< l_t [m]
  double normal_threshold = 0;      ///< F_n = J_c l_n [N]
  double tangential_threshold = 0;  ///< F_t = J_c l_t [N]
  double friction = 0;              ///< mu
  double laser_absorbed_power = 0;  ///< alpha P [W]
  double spot_diameter = 0;         ///< l_f [m]
  double laser_reach = 0;           ///< [m]
  double vaporisation_energy = 0;   ///< q [J/m^3]
  double vaporisation_speed = 0;    ///< v_s [m/s]
  double force_limit = 0;           ///< [N]

  int node_count() const { return static_cast<int>(positions.cols()); }
  int triangle_count() const { return static_cast<int>(triangles.size()); }
  /// The field block (frame, then coefficients) of (node, tool node, state).
  const double* field(int node, int tool_node, FieldState state) const {
    return fields.data() +
           ((static_cast<std::size_t>(node) * static_cast<std::size_t>(tool_node_count) +
             static_cast<std::size_t>(tool_node)) *
                kFieldStates +
            static_cast<std::size_t>(state)) *
               static_cast<std::size_t>(SeparationFields::block_size(degree));
  }
};

/// Checks that the fields belong to the interface and the settings are valid; throws
/// Error naming the mismatch (or a region larger than kMaxRegionTriangles).
SeparationPatch make_separation_patch(const SeparationInterface& interface,
                                      const SeparationFields& fields,
                                      const SeparationSettings& settings);

}  // namespace cohaptic
