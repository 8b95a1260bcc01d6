#include "common/separation/separation_patch.h"

#include <Eigen/Geometry>
#include <cmath>
#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {

SeparationPatch make_separation_patch(const SeparationInterface& interface,
                                      const SeparationFields& fields,
                                      const SeparationSettings& settings) {
  validate(settings);
  if (fields.node_count != interface.node_count())
    throw Error(fmt::format("separation patch: the fields have {} nodes, the interface {}",
                            fields.node_count, interface.node_count()));
  const std::size_t expected = static_cast<std::size_t>(fields.node_count) *
                               fields.tool_node_count * kFieldStates *
                               SeparationFields::block_size(fields.degree);
  if (fields.degree < 1 || fields.tool_node_count < 1 || fields.values.size() != expected)
    throw Error(fmt::format(
        "separation patch: {} field values for degree {} and {} tool nodes (expected {})",
        fields.values.size(), fields.degree, fields.tool_node_count, expected));
  for (std::size_t i = 0; i < fields.values.size(); ++i)
    if (!std::isfinite(fields.values[i]))
      throw Error(fmt::format("separation patch: field value {} is not finite", i));

  SeparationPatch patch;
  patch.positions = interface.positions;
  patch.triangles = interface.triangles;
  patch.neighbours = interface.neighbours;
  patch.open_rim = interface.open_rim;
  patch.regions = node_regions(interface.triangles, interface.node_count());
  for (const Triangle& t : interface.triangles) {
    const Eigen::Vector3d a = interface.positions.col(t[0]), b = interface.positions.col(t[1]),
                          c = interface.positions.col(t[2]);
    const Eigen::Vector3d doubled = (b - a).cross(c - a);
    if (!(doubled.norm() > 0)) throw Error("separation patch: an interface triangle has zero area");
    patch.normals.push_back(doubled.normalized());
    patch.centroids.push_back((a + b + c) / 3);
    patch.areas.push_back(0.5 * doubled.norm());
    patch.interface_area += patch.areas.back();
  }
  patch.region_areas.assign(static_cast<std::size_t>(interface.node_count()), 0.0);
  for (int n = 0; n < interface.node_count(); ++n) {
    const std::span<const int> region = patch.regions.of(n);
    if (region.empty())
      throw Error(fmt::format("separation patch: interface node {} has no triangle", n));
    if (static_cast<int>(region.size()) > SeparationPatch::kMaxRegionTriangles)
      throw Error(fmt::format("separation patch: interface node {} has {} triangles (at most {})",
                              n, region.size(), SeparationPatch::kMaxRegionTriangles));
    for (int t : region) patch.region_areas[n] += patch.areas[t];
  }

  patch.degree = fields.degree;
  patch.tool_node_count = fields.tool_node_count;
  patch.fields = fields.values;

  const FractureSettings& fracture = settings.fracture;
  patch.toughness = fracture.toughness;
  patch.normal_length = fracture.normal_length;
  patch.tangential_length = fracture.tangential_length;
  patch.normal_threshold = fracture.toughness * fracture.normal_length;
  patch.tangential_threshold = fracture.toughness * fracture.tangential_length;
  patch.friction = fracture.friction;
  patch.laser_absorbed_power = settings.laser.absorbed_fraction * settings.laser.power;
  patch.spot_diameter = settings.laser.spot_diameter;
  patch.laser_reach = settings.laser.reach;
  patch.vaporisation_energy = vaporisation_energy_density(settings.tissue);
  patch.vaporisation_speed = vaporisation_speed(settings.laser, settings.tissue);
  patch.force_limit = settings.force_limit;
  return patch;
}

}  // namespace cohaptic
