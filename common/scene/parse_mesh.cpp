#include "common/scene/parse_mesh.h"

#include <fmt/format.h>

#include <cmath>

#include "common/mesh/mesh_limits.h"
#include "common/scene/parse_node_selector.h"

namespace cohaptic {
namespace {

AxisMask parse_axes(const YamlCursor& c) {
  const std::string text = c.text();
  AxisMask mask = 0;
  for (char ch : text) {
    const int axis = ch == 'x' ? 0 : ch == 'y' ? 1 : ch == 'z' ? 2 : -1;
    if (axis < 0 || (mask >> axis) & 1u)
      c.fail("a combination of x, y and z, each at most once (e.g. xyz or z)");
    mask = static_cast<AxisMask>(mask | (1u << axis));
  }
  if (mask == 0) c.fail("at least one axis");
  return mask;
}

}  // namespace

MeshSpec parse_mesh(const YamlCursor& c, double scale, const SceneFiles& files) {
  c.only_keys({"file", "gmsh", "set", "box"});
  MeshSpec mesh;
  const auto file = c.find("file");
  const auto gmsh = c.find("gmsh");
  const auto box = c.find("box");
  if (static_cast<int>(static_cast<bool>(file)) + static_cast<bool>(gmsh) +
          static_cast<bool>(box) !=
      1)
    c.fail("exactly one of file, gmsh or box");
  const auto set = c.find("set");
  if (set && !gmsh) set->fail("only with gmsh (the script's parameters)");
  if (file || gmsh) {
    const YamlCursor& path = file ? *file : *gmsh;
    if (gmsh) files.require_gmsh_allowed(path);
    const std::filesystem::path resolved = files.resolve(path, file ? "mesh file" : "gmsh script");
    if (file) {
      mesh.file = resolved;
    } else {
      GmshScript script{resolved, {}};
      if (set) {
        if (!set->is_map()) set->fail("a map of the script's parameters to numbers");
        for (const std::string& name : set->keys())
          script.parameters[name] = set->at(name).number();
      }
      mesh.gmsh = std::move(script);
    }
  } else {
    box->only_keys({"min", "size", "divisions", "grading", "uniform_cells"});
    BoxMeshSpec spec;
    spec.min_corner = box->at("min").vec3() * scale;
    const YamlCursor size = box->at("size");
    spec.size = size.vec3() * scale;
    if (!(spec.size.array() > 0).all()) size.fail("three positive lengths");
    const YamlCursor divisions = box->at("divisions");
    if (!divisions.is_sequence() || divisions.items().size() != 3)
      divisions.fail("a list of 3 integers");
    const auto parts = divisions.items();
    for (int i = 0; i < 3; ++i) {
      const std::int64_t d = parts[i].integer();
      if (d < 1 || d > 400) parts[i].fail("an integer from 1 to 400");
      spec.divisions[i] = static_cast<int>(d);
    }
    const std::int64_t nodes = (spec.divisions.cast<std::int64_t>().array() + 1).prod();
    if (nodes > kMaxBodyNodes)
      divisions.fail(
          fmt::format("divisions giving at most {} nodes, not {}", kMaxBodyNodes, nodes));
    if (auto grading = box->find("grading")) {
      if (!grading->is_sequence() || grading->items().size() != 3)
        grading->fail("a list of 3 ratios");
      const auto ratios = grading->items();
      for (int i = 0; i < 3; ++i)
        spec.grading[i] = ratios[i].number_in(0.2, 5, false, false, "a ratio from 0.2 to 5");
    }
    if (auto uniform = box->find("uniform_cells")) {
      if (!uniform->is_sequence() || uniform->items().size() != 3)
        uniform->fail("a list of 3 integers");
      const auto cells = uniform->items();
      for (int i = 0; i < 3; ++i) {
        const std::int64_t count = cells[i].integer();
        if (count < 0 || count > spec.divisions[i])
          cells[i].fail(fmt::format("an integer from 0 to the divisions ({})", spec.divisions[i]));
        spec.uniform_cells[i] = static_cast<int>(count);
      }
    }
    mesh.box = spec;
  }
  return mesh;
}

std::vector<FixedRegion> parse_fixed_regions(const YamlCursor& c, double scale) {
  std::vector<FixedRegion> fixed;
  for (const YamlCursor& item : c.items()) {
    item.only_keys({"surface", "box", "plane", "nodes", "axes"});
    FixedRegion region;
    region.nodes = parse_node_selector(item, scale);
    if (auto axes = item.find("axes")) region.axes = parse_axes(*axes);
    fixed.push_back(region);
  }
  if (fixed.empty()) c.fail("at least one fixed region (an unfixed body has no static solution)");
  return fixed;
}

}  // namespace cohaptic
