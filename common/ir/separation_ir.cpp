#include "common/ir/separation_ir.h"

#include <fmt/format.h>

#include <cmath>

#include "common/util/error.h"

namespace cohaptic {
namespace {

// Degrees the fields may have (separation_fields.h's FieldSettings validates the same).
constexpr int kMaxSeparationDegree = 9;
// A unit normal's length may be off by round-off of another producer's arithmetic.
constexpr double kSeparationUnitTolerance = 1e-9;

template <typename... Args>
[[noreturn]] void refuse_separation(fmt::format_string<Args...> format, Args&&... args) {
  throw Error("separation patch: " + fmt::format(format, std::forward<Args>(args)...));
}

void require_positive_setting(double value, const char* what) {
  if (!(std::isfinite(value) && value > 0))
    refuse_separation("{} must be a positive finite number, got {}", what, value);
}

bool separation_vector_finite(const Eigen::Vector3d& v) { return v.allFinite(); }

void check_separation_geometry(const SeparationPatch& p) {
  const int nodes = p.node_count(), triangles = p.triangle_count();
  if (nodes < 3 || triangles < 1) refuse_separation("{} nodes and {} triangles", nodes, triangles);
  if (!p.positions.allFinite()) refuse_separation("a node position is not finite");
  const auto per_triangle = [&](std::size_t size, const char* what) {
    if (size != static_cast<std::size_t>(triangles))
      refuse_separation("{} {} for {} triangles", size, what, triangles);
  };
  per_triangle(p.neighbours.size(), "neighbour triples");
  per_triangle(p.open_rim.size(), "crack flags");
  per_triangle(p.normals.size(), "normals");
  per_triangle(p.centroids.size(), "centroids");
  per_triangle(p.areas.size(), "areas");
  for (int t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) {
      const int node = p.triangles[t][k], neighbour = p.neighbours[t][k];
      if (node < 0 || node >= nodes)
        refuse_separation("triangle {} names node {} ({} nodes)", t, node, nodes);
      if (neighbour < -1 || neighbour >= triangles)
        refuse_separation("triangle {} names neighbour {} ({} triangles)", t, neighbour, triangles);
    }
    if (p.open_rim[t] > 7)
      refuse_separation("triangle {} has crack flags {} (three edge bits at most)", t,
                        p.open_rim[t]);
    if (!separation_vector_finite(p.normals[t]) ||
        std::abs(p.normals[t].norm() - 1) > kSeparationUnitTolerance)
      refuse_separation("triangle {} has a normal that is not a unit vector", t);
    if (!separation_vector_finite(p.centroids[t]))
      refuse_separation("triangle {} has a non-finite centroid", t);
    require_positive_setting(p.areas[t], "a triangle's area");
  }
  require_positive_setting(p.interface_area, "interface_area");
}

void check_separation_regions(const SeparationPatch& p) {
  const NodeRegions& r = p.regions;
  const int nodes = p.node_count(), triangles = p.triangle_count();
  if (static_cast<int>(r.offsets.size()) != nodes + 1 || r.offsets.front() != 0 ||
      r.offsets.back() != static_cast<int>(r.triangles.size()))
    refuse_separation(
        "region offsets do not cover the region list ({} offsets for {} nodes, {} entries)",
        r.offsets.size(), nodes, r.triangles.size());
  for (int n = 0; n < nodes; ++n) {
    const int size = r.offsets[n + 1] - r.offsets[n];
    if (size < 1 || size > SeparationPatch::kMaxRegionTriangles)
      refuse_separation("node {} has a region of {} triangles (1 to {})", n, size,
                        SeparationPatch::kMaxRegionTriangles);
  }
  for (int t : r.triangles)
    if (t < 0 || t >= triangles)
      refuse_separation("a region names triangle {} ({} triangles)", t, triangles);
  if (static_cast<int>(p.region_areas.size()) != nodes)
    refuse_separation("{} region areas for {} nodes", p.region_areas.size(), nodes);
  for (double area : p.region_areas) require_positive_setting(area, "a region's area");
}

void check_separation_fields_and_settings(const SeparationPatch& p) {
  if (p.degree < 1 || p.degree > kMaxSeparationDegree)
    refuse_separation("degree {} (1 to {})", p.degree, kMaxSeparationDegree);
  if (p.tool_node_count < 1 || p.tool_node_count > p.node_count())
    refuse_separation("{} tool nodes ({} patch nodes)", p.tool_node_count, p.node_count());
  const std::size_t expected = static_cast<std::size_t>(p.node_count()) *
                               static_cast<std::size_t>(p.tool_node_count) * kFieldStates *
                               static_cast<std::size_t>(SeparationFields::block_size(p.degree));
  if (p.fields.size() != expected)
    refuse_separation("{} field values, expected {}", p.fields.size(), expected);
  for (std::size_t i = 0; i < p.fields.size(); ++i)
    if (!std::isfinite(p.fields[i])) refuse_separation("field value {} is not finite", i);
  require_positive_setting(p.toughness, "toughness (J_c)");
  require_positive_setting(p.normal_length, "normal_length (l_n)");
  require_positive_setting(p.tangential_length, "tangential_length (l_t)");
  require_positive_setting(p.normal_threshold, "normal_threshold (F_n)");
  require_positive_setting(p.tangential_threshold, "tangential_threshold (F_t)");
  if (!(std::isfinite(p.friction) && p.friction >= 0))
    refuse_separation("friction {} is not >= 0", p.friction);
  require_positive_setting(p.laser_absorbed_power, "laser_absorbed_power (alpha P)");
  require_positive_setting(p.spot_diameter, "spot_diameter (l_f)");
  require_positive_setting(p.laser_reach, "laser_reach");
  require_positive_setting(p.vaporisation_energy, "vaporisation_energy (q)");
  require_positive_setting(p.vaporisation_speed, "vaporisation_speed (v_s)");
  require_positive_setting(p.force_limit, "force_limit");
}

bool separation_weights_valid(const Eigen::Vector3d& w) {
  return w.allFinite() && (w.array() >= 0).all() && std::abs(w.sum() - 1) < 1e-9;
}

void check_separation_tool(const SeparationPatch& p, const SeparationIr& ir) {
  if (!(std::isfinite(ir.tool.grasp_reach) && ir.tool.grasp_reach >= 0))
    refuse_separation("grasp_reach {} is not a finite length >= 0", ir.tool.grasp_reach);
  if (ir.tool.contact != ContactMode::grasp && ir.tool.contact != ContactMode::push)
    refuse_separation("the tool's contact {} is not grasp or push",
                      static_cast<int>(ir.tool.contact));
  const SeparationContact& c = ir.tool_state.contact;
  if (c.mode != ContactMode::none && c.mode != ContactMode::grasp && c.mode != ContactMode::push)
    refuse_separation("contact mode {} is not none, grasp or push", static_cast<int>(c.mode));
  if (c.mode != ContactMode::none) {
    if (c.point.triangle < 0 || c.point.triangle >= p.triangle_count())
      refuse_separation("the contact is on triangle {} ({} triangles)", c.point.triangle,
                        p.triangle_count());
    for (int j : c.point.tool_nodes)
      if (j < 0 || j >= p.tool_node_count)
        refuse_separation("the contact names tool node {} ({})", j, p.tool_node_count);
    if (!separation_weights_valid(c.point.weights) ||
        !separation_weights_valid(c.point.tool_weights))
      refuse_separation("the contact's area coordinates are not non-negative weights summing to 1");
    if (!separation_vector_finite(c.position) || !separation_vector_finite(c.tool_offset) ||
        !separation_vector_finite(c.last_tool))
      refuse_separation("the contact has a non-finite position");
  }
  if (!separation_vector_finite(ir.tool_state.fibre.last_tip))
    refuse_separation("the fibre's last tip is not finite");
}

}  // namespace

std::size_t SeparationIr::size_bytes() const {
  if (!patch) return 0;
  const auto nodes = static_cast<std::size_t>(patch->node_count());
  const auto triangles = static_cast<std::size_t>(patch->triangle_count());
  constexpr std::size_t kScalars =
      14 * sizeof(double) + 2 * sizeof(std::int32_t);  // degree .. force limit
  const std::size_t geometry =
      nodes * (3 + 1) * sizeof(double) +
      triangles * (6 * sizeof(std::int32_t) + 1 + 7 * sizeof(double)) +
      (patch->regions.offsets.size() + patch->regions.triangles.size()) * sizeof(std::int32_t);
  constexpr std::size_t kInstrument =
      1 + 1 + 4 * sizeof(std::int32_t) + 16 * sizeof(double) + 2;  // settings, contact, fibre, jaws
  return kScalars + geometry + patch->fields.size() * sizeof(double) +
         (triangles + 1) * sizeof(double) + kInstrument;
}

void validate_separation_ir(const SeparationIr& ir) {
  if (!ir.patch) refuse_separation("missing");
  const SeparationPatch& p = *ir.patch;
  check_separation_geometry(p);
  check_separation_regions(p);
  check_separation_fields_and_settings(p);
  if (static_cast<int>(ir.state.separated.size()) != p.triangle_count())
    refuse_separation("{} separated shares for {} triangles", ir.state.separated.size(),
                      p.triangle_count());
  for (std::size_t t = 0; t < ir.state.separated.size(); ++t)
    if (!(ir.state.separated[t] >= 0 && ir.state.separated[t] <= 1))
      refuse_separation("triangle {}'s separated share {} is not in [0, 1]", t,
                        ir.state.separated[t]);
  if (!(std::isfinite(ir.state.separated_area) && ir.state.separated_area >= 0))
    refuse_separation("separated_area {} is not a finite area >= 0", ir.state.separated_area);
  check_separation_tool(p, ir);
}

}  // namespace cohaptic
