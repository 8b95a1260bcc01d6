#include "proto/wire/separation_convert.h"

#include <fmt/format.h>

#include <climits>
#include <cmath>

#include "common/util/error.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic::wire {
namespace {

template <typename... Args>
[[noreturn]] void refuse_separation_wire(fmt::format_string<Args...> format, Args&&... args) {
  throw cohaptic::Error("separation patch: " + fmt::format(format, std::forward<Args>(args)...));
}

template <typename Field>
void add_separation_doubles(const double* values, std::size_t count, Field* out) {
  out->Reserve(static_cast<int>(count));
  for (std::size_t i = 0; i < count; ++i) out->AddAlreadyReserved(values[i]);
}

template <typename Field>
void add_separation_vectors(const std::vector<Eigen::Vector3d>& vectors, Field* out) {
  out->Reserve(static_cast<int>(3 * vectors.size()));
  for (const Eigen::Vector3d& v : vectors)
    for (int a = 0; a < 3; ++a) out->AddAlreadyReserved(v[a]);
}

int separation_index(std::uint32_t value, const char* what) {
  if (value > static_cast<std::uint32_t>(INT_MAX))
    refuse_separation_wire("{} = {} is out of range", what, value);
  return static_cast<int>(value);
}

std::vector<Eigen::Vector3d> read_separation_vectors(
    const google::protobuf::RepeatedField<double>& values, int count, const char* what) {
  if (values.size() != 3 * count)
    refuse_separation_wire("{} has {} values, expected 3 x {}", what, values.size(), count);
  std::vector<Eigen::Vector3d> out(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i)
    out[static_cast<std::size_t>(i)] = {values[3 * i], values[3 * i + 1], values[3 * i + 2]};
  return out;
}

Eigen::Vector3d read_separation_weights(const google::protobuf::RepeatedField<double>& values,
                                        const char* what) {
  if (values.size() != 3)
    refuse_separation_wire("{} has {} values, expected 3", what, values.size());
  return {values[0], values[1], values[2]};
}

cohaptic::SeparationContact contact_from_wire(const SeparationContact& w) {
  cohaptic::SeparationContact contact;
  if (w.mode() > 2) refuse_separation_wire("contact mode {} is not none, grasp or push", w.mode());
  contact.mode = static_cast<ContactMode>(w.mode());
  contact.point.triangle = separation_index(w.triangle(), "contact triangle");
  contact.point.weights = read_separation_weights(w.weights(), "contact weights");
  if (w.tool_nodes_size() != 3)
    refuse_separation_wire("contact tool_nodes has {} entries, expected 3", w.tool_nodes_size());
  for (int k = 0; k < 3; ++k)
    contact.point.tool_nodes[static_cast<std::size_t>(k)] =
        separation_index(w.tool_nodes(k), "contact tool node");
  contact.point.tool_weights = read_separation_weights(w.tool_weights(), "contact tool_weights");
  contact.position = from_wire(w.position());
  contact.tool_offset = from_wire(w.tool_offset());
  contact.last_tool = from_wire(w.last_tool());
  return contact;
}

}  // namespace

void separation_to_wire(const cohaptic::SeparationIr& ir, SeparationPatch* out) {
  const cohaptic::SeparationPatch& p = *ir.patch;
  add_separation_doubles(p.positions.data(), static_cast<std::size_t>(p.positions.size()),
                         out->mutable_positions());
  for (const Triangle& t : p.triangles)
    for (int node : t) out->add_triangles(static_cast<std::uint32_t>(node));
  for (const std::array<int, 3>& n : p.neighbours)
    for (int neighbour : n) out->add_neighbours(neighbour);
  out->set_open_rim(std::string(p.open_rim.begin(), p.open_rim.end()));
  add_separation_vectors(p.normals, out->mutable_normals());
  add_separation_vectors(p.centroids, out->mutable_centroids());
  add_separation_doubles(p.areas.data(), p.areas.size(), out->mutable_areas());
  for (int offset : p.regions.offsets) out->add_region_offsets(static_cast<std::uint32_t>(offset));
  for (int t : p.regions.triangles) out->add_region_triangles(static_cast<std::uint32_t>(t));
  add_separation_doubles(p.region_areas.data(), p.region_areas.size(), out->mutable_region_areas());
  out->set_interface_area(p.interface_area);
  out->set_degree(static_cast<std::uint32_t>(p.degree));
  out->set_tool_node_count(static_cast<std::uint32_t>(p.tool_node_count));
  add_separation_doubles(p.fields.data(), p.fields.size(), out->mutable_fields());
  out->set_toughness(p.toughness);
  out->set_normal_length(p.normal_length);
  out->set_tangential_length(p.tangential_length);
  out->set_normal_threshold(p.normal_threshold);
  out->set_tangential_threshold(p.tangential_threshold);
  out->set_friction(p.friction);
  out->set_laser_absorbed_power(p.laser_absorbed_power);
  out->set_spot_diameter(p.spot_diameter);
  out->set_laser_reach(p.laser_reach);
  out->set_vaporisation_energy(p.vaporisation_energy);
  out->set_vaporisation_speed(p.vaporisation_speed);
  out->set_force_limit(p.force_limit);
  add_separation_doubles(ir.state.separated.data(), ir.state.separated.size(),
                         out->mutable_separated());
  out->set_separated_area(ir.state.separated_area);
  out->set_laser_tool(ir.tool.laser);
  out->set_grasp_reach(ir.tool.grasp_reach);
  out->set_tool_contact(static_cast<std::uint32_t>(ir.tool.contact));
  const cohaptic::SeparationContact& c = ir.tool_state.contact;
  if (c.mode != ContactMode::none) {
    SeparationContact* w = out->mutable_contact();
    w->set_mode(static_cast<std::uint32_t>(c.mode));
    w->set_triangle(static_cast<std::uint32_t>(c.point.triangle));
    add_separation_doubles(c.point.weights.data(), 3, w->mutable_weights());
    for (int j : c.point.tool_nodes) w->add_tool_nodes(static_cast<std::uint32_t>(j));
    add_separation_doubles(c.point.tool_weights.data(), 3, w->mutable_tool_weights());
    to_wire(c.position, w->mutable_position());
    to_wire(c.tool_offset, w->mutable_tool_offset());
    to_wire(c.last_tool, w->mutable_last_tool());
  }
  out->set_fibre_firing(ir.tool_state.fibre.firing);
  to_wire(ir.tool_state.fibre.last_tip, out->mutable_fibre_last_tip());
  out->set_jaws_closed(ir.tool_state.jaws_closed);
}

cohaptic::SeparationIr separation_from_wire(const SeparationPatch& w) {
  auto p = std::make_shared<cohaptic::SeparationPatch>();
  if (w.positions_size() % 3 != 0)
    refuse_separation_wire("{} position values, not a multiple of 3", w.positions_size());
  const int nodes = w.positions_size() / 3;
  p->positions.resize(3, nodes);
  for (int i = 0; i < w.positions_size(); ++i) p->positions.data()[i] = w.positions(i);
  if (w.triangles_size() % 3 != 0)
    refuse_separation_wire("{} triangle corners, not a multiple of 3", w.triangles_size());
  const int triangles = w.triangles_size() / 3;
  if (w.neighbours_size() != 3 * triangles)
    refuse_separation_wire("{} neighbours for {} triangles", w.neighbours_size(), triangles);
  p->triangles.resize(static_cast<std::size_t>(triangles));
  p->neighbours.resize(static_cast<std::size_t>(triangles));
  for (int t = 0; t < triangles; ++t)
    for (int k = 0; k < 3; ++k) {
      p->triangles[static_cast<std::size_t>(t)][static_cast<std::size_t>(k)] =
          separation_index(w.triangles(3 * t + k), "triangle corner");
      p->neighbours[static_cast<std::size_t>(t)][static_cast<std::size_t>(k)] =
          w.neighbours(3 * t + k);
    }
  p->open_rim.assign(w.open_rim().begin(), w.open_rim().end());
  p->normals = read_separation_vectors(w.normals(), triangles, "normals");
  p->centroids = read_separation_vectors(w.centroids(), triangles, "centroids");
  p->areas.assign(w.areas().begin(), w.areas().end());
  for (std::uint32_t offset : w.region_offsets())
    p->regions.offsets.push_back(separation_index(offset, "region offset"));
  for (std::uint32_t t : w.region_triangles())
    p->regions.triangles.push_back(separation_index(t, "region triangle"));
  if (p->regions.offsets.empty()) refuse_separation_wire("no region offsets");
  p->region_areas.assign(w.region_areas().begin(), w.region_areas().end());
  p->interface_area = w.interface_area();
  p->degree = separation_index(w.degree(), "degree");
  p->tool_node_count = separation_index(w.tool_node_count(), "tool_node_count");
  p->fields.assign(w.fields().begin(), w.fields().end());
  p->toughness = w.toughness();
  p->normal_length = w.normal_length();
  p->tangential_length = w.tangential_length();
  p->normal_threshold = w.normal_threshold();
  p->tangential_threshold = w.tangential_threshold();
  p->friction = w.friction();
  p->laser_absorbed_power = w.laser_absorbed_power();
  p->spot_diameter = w.spot_diameter();
  p->laser_reach = w.laser_reach();
  p->vaporisation_energy = w.vaporisation_energy();
  p->vaporisation_speed = w.vaporisation_speed();
  p->force_limit = w.force_limit();

  cohaptic::SeparationIr ir;
  ir.state.separated.assign(w.separated().begin(), w.separated().end());
  ir.state.separated_area = w.separated_area();
  ir.tool.laser = w.laser_tool();
  ir.tool.grasp_reach = w.grasp_reach();
  if (w.tool_contact() > static_cast<std::uint32_t>(ContactMode::push))
    refuse_separation_wire("tool_contact {} is neither grasp (1) nor push (2)", w.tool_contact());
  // 0: written before tools could push, forceps.
  ir.tool.contact =
      w.tool_contact() == 0 ? ContactMode::grasp : static_cast<ContactMode>(w.tool_contact());
  if (w.has_contact()) ir.tool_state.contact = contact_from_wire(w.contact());
  ir.tool_state.fibre.firing = w.fibre_firing();
  ir.tool_state.fibre.last_tip = from_wire(w.fibre_last_tip());
  ir.tool_state.jaws_closed = w.jaws_closed();
  ir.patch = std::move(p);
  validate_separation_ir(ir);
  return ir;
}

}  // namespace cohaptic::wire
