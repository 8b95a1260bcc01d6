#include "common/scene/parse_mass_spring.h"

#include <fmt/format.h>

#include <cmath>

#include "common/mass_spring/tube_network.h"
#include "common/mesh/mesh_limits.h"
#include "common/scene/parse_node_selector.h"

namespace cohaptic {
namespace {

TubeGeometry parse_tube(const YamlCursor& c, double scale) {
  c.only_keys({"centre_line", "radius", "sections", "section_spacing", "up"});
  TubeGeometry tube;
  const YamlCursor line = c.at("centre_line");
  for (const YamlCursor& point : line.items()) tube.centre_line.push_back(point.vec3() * scale);
  if (tube.centre_line.size() < 2) line.fail("a list of at least 2 points");
  double length = 0;
  for (std::size_t i = 1; i < tube.centre_line.size(); ++i) {
    const double span = (tube.centre_line[i] - tube.centre_line[i - 1]).norm();
    if (!(span > 0)) line.items()[i].fail("a point different from the one before");
    length += span;
  }
  tube.radius = c.at("radius").positive("a positive radius") * scale;
  const auto sections = c.find("sections");
  const auto spacing = c.find("section_spacing");
  if (static_cast<bool>(sections) == static_cast<bool>(spacing))
    c.fail("exactly one of sections or section_spacing");
  if (sections) {
    const std::int64_t count = sections->integer();
    if (count < 2 || count > 100000) sections->fail("an integer from 2 to 100000");
    tube.sections = static_cast<int>(count);
  } else {
    const double step = spacing->positive("a positive length") * scale;
    const double count = std::round(length / step) + 1;
    if (count < 2 || count > 100000)
      spacing->fail("a spacing giving 2 to 100000 sections along the centre line");
    tube.sections = static_cast<int>(count);
  }
  // tube_network: a centre node and kRingNodes ring nodes per section.
  const std::int64_t nodes = std::int64_t{kSectionNodes} * tube.sections;
  if (nodes > kMaxBodyNodes) {
    const std::string expected =
        fmt::format("at most {} nodes ({} per section), not {} ({} sections)", kMaxBodyNodes,
                    kSectionNodes, nodes, tube.sections);
    if (sections) sections->fail("sections giving " + expected);
    spacing->fail("a spacing giving " + expected);
  }
  if (auto up = c.find("up")) {
    tube.up = up->direction("a non-zero vector");
  }
  return tube;
}

SupportPlane parse_plane(const YamlCursor& c, double scale) {
  c.only_keys({"point", "normal", "static_friction", "dynamic_friction"});
  SupportPlane plane;
  plane.point = c.at("point").vec3() * scale;
  plane.normal = c.at("normal").direction("a non-zero normal vector");
  plane.static_friction =
      c.at("static_friction").number_in(0, INFINITY, false, true, "a friction coefficient >= 0");
  const YamlCursor dynamic = c.at("dynamic_friction");
  plane.dynamic_friction = dynamic.number_in(0, plane.static_friction, false, false,
                                             "a friction coefficient from 0 up to the static one");
  return plane;
}

// The several-objects paper's object A: `lattice: {box: {min, size, divisions}, spring_stiffness,
// spring_damping, node_mass}`.
SpringLatticeSpec parse_lattice(const YamlCursor& c, double scale) {
  c.only_keys({"box", "spring_stiffness", "spring_damping", "node_mass"});
  SpringLatticeSpec lattice;
  const YamlCursor box = c.at("box");
  box.only_keys({"min", "size", "divisions"});
  lattice.min_corner = box.at("min").vec3() * scale;
  const YamlCursor size = box.at("size");
  lattice.size = size.vec3() * scale;
  if (!(lattice.size.array() > 0).all()) size.fail("three positive lengths");
  const YamlCursor divisions = box.at("divisions");
  if (!divisions.is_sequence() || divisions.items().size() != 3)
    divisions.fail("a list of 3 integers");
  const auto parts = divisions.items();
  for (int i = 0; i < 3; ++i) {
    const std::int64_t d = parts[static_cast<std::size_t>(i)].integer();
    if (d < 1 || d > 100) parts[static_cast<std::size_t>(i)].fail("an integer from 1 to 100");
    lattice.divisions[i] = static_cast<int>(d);
  }
  const std::int64_t nodes = (lattice.divisions.cast<std::int64_t>().array() + 1).prod();
  if (nodes > kMaxBodyNodes)
    divisions.fail(fmt::format("divisions giving at most {} nodes, not {}", kMaxBodyNodes, nodes));
  lattice.spring_stiffness = c.at("spring_stiffness").positive("a positive stiffness in N/m");
  lattice.spring_damping =
      c.at("spring_damping").number_in(0, INFINITY, false, true, "a damping in N s/m, >= 0");
  lattice.node_mass = c.at("node_mass").positive("a positive mass in kg");
  return lattice;
}

HeatedRegion parse_heated(const YamlCursor& c, double scale) {
  c.only_keys({"box", "temperature_rise", "expansion_coefficient", "coupling"});
  HeatedRegion region;
  const YamlCursor box = c.at("box");
  box.only_keys({"min", "max"});
  region.box_min = box.at("min").vec3() * scale;
  region.box_max = box.at("max").vec3() * scale;
  if ((region.box_max.array() < region.box_min.array()).any())
    box.at("max").fail("a corner not below min on any axis");
  region.temperature_rise =
      c.at("temperature_rise").number_in(0, INFINITY, false, true, "a temperature rise >= 0 in K");
  region.expansion_coefficient =
      c.at("expansion_coefficient")
          .number_in(0, INFINITY, false, true, "a linear expansion coefficient >= 0 in 1/K");
  if (auto coupling = c.find("coupling"))
    region.coupling = coupling->positive("a positive constant c");
  const double factor =
      1 - region.coupling * region.expansion_coefficient * region.temperature_rise;
  if (!(factor > 0))
    c.fail_message(fmt::format(
        "coupling x expansion_coefficient x temperature_rise is {}: Eq. (7) would leave the "
        "springs with no stiffness (it must stay below 1)",
        1 - factor));
  return region;
}

}  // namespace

MassSpringObjectSpec parse_mass_spring_object(const YamlCursor& c, double scale) {
  c.only_keys({"name", "model", "tube", "lattice", "material", "fixed", "node_damping", "plane",
               "tool_friction", "gravity", "time_step", "heated", "ir"});
  MassSpringObjectSpec object;
  const auto tube = c.find("tube");
  const auto lattice = c.find("lattice");
  if (static_cast<bool>(tube) == static_cast<bool>(lattice))
    c.fail("exactly one of tube or lattice");
  if (lattice) {
    // A lattice's springs are given directly: no material to derive them from.
    if (auto material = c.find("material"))
      material->fail_message(
          "a lattice takes no material (its springs and masses are in lattice:)");
    object.lattice = parse_lattice(*lattice, scale);
    object.node_damping = 0;
    if (auto beta = c.find("node_damping"))
      object.node_damping = beta->number_in(0, INFINITY, false, true, "beta in N s/m, >= 0");
  } else {
    if (auto beta = c.find("node_damping"))
      beta->fail_message("a tube's node_damping goes in its material");
    object.tube = parse_tube(*tube, scale);
    const YamlCursor material = c.at("material");
    material.only_keys({"youngs_modulus", "density", "spring_damping", "node_damping"});
    object.material.youngs_modulus =
        material.at("youngs_modulus").positive("a positive modulus in Pa");
    object.material.density = material.at("density").positive("a positive density in kg/m^3");
    if (auto alpha = material.find("spring_damping"))
      object.material.spring_damping =
          alpha->number_in(0, INFINITY, false, true, "alpha of Eq. (2) in s, >= 0");
    if (auto beta = material.find("node_damping"))
      object.node_damping = beta->number_in(0, INFINITY, false, true, "beta in N s/m, >= 0");
  }

  if (auto fixed = c.find("fixed"))
    for (const YamlCursor& item : fixed->items()) {
      item.only_keys({"surface", "box", "plane", "nodes"});  // a held node is held on every axis
      object.fixed.push_back(parse_node_selector(item, scale));
    }
  if (auto plane = c.find("plane")) object.plane = parse_plane(*plane, scale);
  if (auto mu = c.find("tool_friction"))
    object.tool_friction = mu->number_in(0, INFINITY, false, true, "a friction coefficient >= 0");
  if (auto gravity = c.find("gravity"))
    object.gravity = gravity->vec3();  // m/s^2 whatever the length unit
  if (auto step = c.find("time_step"))
    object.time_step = step->number_in(0, 0.1, true, false, "a time step in s, in (0, 0.1]");
  if (auto heated = c.find("heated"))
    for (const YamlCursor& item : heated->items())
      object.heated.push_back(parse_heated(item, scale));
  if (auto ir = c.find("ir")) {
    ir->only_keys({"sections", "rate_hz", "near_distance"});
    if (auto sections = ir->find("sections")) {
      const std::int64_t count = sections->integer();
      if (count < 1 || count > 100000) sections->fail("an integer from 1 to 100000");
      object.ir.sections = static_cast<int>(count);
    }
    if (auto rate = ir->find("rate_hz"))
      object.ir.rate_hz = rate->number_in(0, 100000, true, false, "a rate in Hz, in (0, 100000]");
    if (auto near = ir->find("near_distance"))
      object.ir.near_distance = near->positive("a positive length") * scale;
  }
  return object;
}

}  // namespace cohaptic
