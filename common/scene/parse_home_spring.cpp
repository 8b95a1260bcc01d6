#include "common/scene/parse_home_spring.h"

#include "common/mesh/mesh_limits.h"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

namespace cohaptic {
namespace {

constexpr double kRadiansPerDegree = std::numbers::pi / 180;

TissueGridSpec parse_tissue_grid(const YamlCursor& c, double scale) {
  c.only_keys({"min", "size", "divisions"});
  TissueGridSpec grid;
  grid.min = c.at("min").vec3() * scale;
  const YamlCursor size = c.at("size");
  if (!size.is_sequence() || size.items().size() != 2) size.fail("a list of 2 positive lengths");
  const YamlCursor divisions = c.at("divisions");
  if (!divisions.is_sequence() || divisions.items().size() != 2)
    divisions.fail("a list of 2 integers");
  for (int axis = 0; axis < 2; ++axis) {
    grid.size[axis] =
        size.items()[static_cast<std::size_t>(axis)].positive("a positive length") * scale;
    const YamlCursor count = divisions.items()[static_cast<std::size_t>(axis)];
    const std::int64_t d = count.integer();
    if (d < 1 || d > 1000) count.fail("an integer from 1 to 1000");
    grid.divisions[axis] = static_cast<int>(d);
  }
  const std::int64_t vertices = (grid.divisions.cast<std::int64_t>().array() + 1).prod();
  if (vertices > kMaxBodyNodes)
    divisions.fail(
        fmt::format("divisions giving at most {} vertices, not {}", kMaxBodyNodes, vertices));
  return grid;
}

}  // namespace

HomeSpringObjectSpec parse_home_spring_object(const YamlCursor& c, double scale,
                                              const SceneFiles& files) {
  c.only_keys({"name", "model", "surface", "stiffness", "damping", "patch_radius", "display"});
  HomeSpringObjectSpec object;

  const YamlCursor surface = c.at("surface");
  surface.only_keys({"file", "grid"});
  const auto file = surface.find("file");
  const auto grid = surface.find("grid");
  if (static_cast<bool>(file) == static_cast<bool>(grid))
    surface.fail("exactly one of file (a FreeSurfer .asc surface) or grid");
  if (file) {
    object.surface_file = files.resolve(*file, "surface file");
  } else {
    object.grid = parse_tissue_grid(*grid, scale);
  }

  const YamlCursor stiffness = c.at("stiffness");
  stiffness.only_keys({"home", "neighbour"});
  object.home_stiffness = stiffness.at("home").positive("a positive stiffness k1 in N/m");
  object.neighbour_stiffness =
      stiffness.at("neighbour").number_in(0, INFINITY, false, true, "a stiffness k2 >= 0 in N/m");
  if (const auto damping = c.find("damping"))
    object.damping = damping->number_in(0, INFINITY, false, true,
                                        "a damping c >= 0 in N s/m (0: no viscous element)");
  object.patch_radius = c.at("patch_radius").positive("a positive length") * scale;

  const YamlCursor display = c.at("display");
  display.only_keys({"deformation", "radius"});
  if (auto deformation = display.find("deformation"))
    object.display = deformation->choice({"polynomial", "ffd"}) == "polynomial"
                         ? TissueDisplayKind::polynomial
                         : TissueDisplayKind::ffd;
  object.display_radius = display.at("radius").positive("a positive radius of influence") * scale;
  return object;
}

InstrumentSpec parse_instrument(const YamlCursor& c, double scale, bool forceps) {
  InstrumentSpec instrument;
  instrument.trocar = c.at("trocar").vec3() * scale;
  const auto jaws = c.find("jaws");
  if (!forceps) {
    if (jaws) jaws->fail_message("a probe has no jaws (use shape: forceps)");
    return instrument;
  }
  if (!jaws) return instrument;
  jaws->only_keys({"length", "open_angle_deg", "closing_step_deg", "opening"});
  if (auto length = jaws->find("length"))
    instrument.jaw_length = length->positive("a positive jaw length") * scale;
  if (auto open = jaws->find("open_angle_deg"))
    instrument.open_angle =
        open->number_in(0, 90, true, true, "an angle in (0, 90) degrees") * kRadiansPerDegree;
  if (auto step = jaws->find("closing_step_deg"))
    instrument.closing_step =
        step->number_in(0, instrument.open_angle / kRadiansPerDegree, true, false,
                        "an angle in degrees, positive and at most open_angle_deg") *
        kRadiansPerDegree;
  else if (instrument.closing_step > instrument.open_angle)
    jaws->at("open_angle_deg")
        .fail_message(fmt::format(
            "open_angle_deg {:g} is below the closing step (closing_step_deg, by default {:.4g}): "
            "give a closing_step_deg of at most {:g}",
            instrument.open_angle / kRadiansPerDegree, instrument.closing_step / kRadiansPerDegree,
            instrument.open_angle / kRadiansPerDegree));
  if (auto opening = jaws->find("opening"))
    instrument.opening = opening->direction("a non-zero direction");
  return instrument;
}

}  // namespace cohaptic
