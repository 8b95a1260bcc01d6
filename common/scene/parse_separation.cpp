#include "common/scene/parse_separation.h"

#include <fmt/format.h>

#include <cmath>
#include <set>

#include "common/mesh/mesh_limits.h"
#include "common/scene/parse_mesh.h"
#include "common/scene/parse_node_selector.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

double separation_length(const YamlCursor& c, double scale) {
  const double length = c.positive("a positive length") * scale;
  if (!std::isfinite(length)) c.fail("a finite length");
  return length;
}

int separation_count(const YamlCursor& c, int low, int high) {
  const std::int64_t value = c.integer();
  if (value < low || value > high)
    c.fail("an integer from " + std::to_string(low) + " to " + std::to_string(high));
  return static_cast<int>(value);
}

double separation_reach(const YamlCursor& c, double scale) {
  const double length = c.number_in(0, INFINITY, false, true, "a length >= 0") * scale;
  if (!std::isfinite(length)) c.fail("a finite length");
  return length;
}

LinearElasticMaterial parse_separation_layer_material(const YamlCursor& c) {
  c.only_keys({"youngs_modulus", "poisson_ratio"});
  LinearElasticMaterial material;
  material.youngs_modulus =
      c.at("youngs_modulus").number_in(0, INFINITY, true, true, "a positive modulus in Pa");
  material.poisson_ratio =
      c.at("poisson_ratio").number_in(-1, 0.5, true, true, "a number in (-1, 0.5)");
  return material;
}

TwoLayerBoxes parse_separation_layers(const YamlCursor& c, double scale) {
  c.only_keys({"origin", "size", "flap_thickness", "base_thickness", "divisions", "flap_layers",
               "base_layers", "flap_material", "base_material"});
  TwoLayerBoxes layers;
  if (auto origin = c.find("origin")) {
    layers.origin = origin->vec3() * scale;
    if (!layers.origin.allFinite()) origin->fail("three finite lengths");
  }
  const std::vector<YamlCursor> size = c.at("size").items();
  if (size.size() != 2) c.at("size").fail("a list of two lengths [a, b]");
  layers.size =
      Eigen::Vector2d(separation_length(size[0], scale), separation_length(size[1], scale));
  layers.pulled_thickness = separation_length(c.at("flap_thickness"), scale);
  layers.base_thickness = separation_length(c.at("base_thickness"), scale);
  const std::vector<YamlCursor> divisions = c.at("divisions").items();
  if (divisions.size() != 2) c.at("divisions").fail("a list of two cell counts [nx, ny]");
  layers.divisions = Eigen::Vector2i(separation_count(divisions[0], 1, 200),
                                     separation_count(divisions[1], 1, 200));
  if (auto flap = c.find("flap_layers")) layers.pulled_layers = separation_count(*flap, 1, 50);
  if (auto base = c.find("base_layers")) layers.base_layers = separation_count(*base, 1, 50);
  // make_two_layer_boxes meshes each layer as a box of divisions x layers cells.
  const std::int64_t nodes = std::int64_t{layers.divisions.x() + 1} * (layers.divisions.y() + 1) *
                             (layers.pulled_layers + 1 + layers.base_layers + 1);
  if (nodes > kMaxBodyNodes)
    c.at("divisions")
        .fail_message(fmt::format(
            "[{}, {}] with {} flap and {} base layers make {} nodes ({} x {} x ({} + {})), "
            "more than the {} a body may have",
            layers.divisions.x(), layers.divisions.y(), layers.pulled_layers, layers.base_layers,
            nodes, layers.divisions.x() + 1, layers.divisions.y() + 1, layers.pulled_layers + 1,
            layers.base_layers + 1, kMaxBodyNodes));
  if (auto material = c.find("flap_material"))
    layers.pulled_material = parse_separation_layer_material(*material);
  if (auto material = c.find("base_material"))
    layers.base_material = parse_separation_layer_material(*material);
  return layers;
}

SeparationBodySpec parse_separating_body(const YamlCursor& c, double scale,
                                         const SceneFiles& files) {
  c.only_keys({"mesh", "material", "fixed"});
  SeparationBodySpec body;
  body.mesh = parse_mesh(c.at("mesh"), scale, files);
  body.material = parse_separation_layer_material(c.at("material"));
  body.fixed = parse_fixed_regions(c.at("fixed"), scale);
  return body;
}

SeparationMeshesSpec parse_separation_meshes(const YamlCursor& c, double scale,
                                             const SceneFiles& files) {
  SeparationMeshesSpec meshes;
  meshes.pulled = parse_separating_body(c.at("pulled"), scale, files);
  meshes.base = parse_separating_body(c.at("base"), scale, files);
  if (auto interface = c.find("interface")) {
    interface->only_keys({"tolerance", "sealed"});
    if (auto tolerance = interface->find("tolerance"))
      meshes.interface_tolerance = separation_length(*tolerance, scale);
    if (auto sealed = interface->find("sealed"))
      for (const YamlCursor& item : sealed->items()) {
        item.only_keys({"surface", "box", "plane", "nodes"});
        meshes.sealed.push_back(parse_node_selector(item, scale));
      }
  }
  return meshes;
}

FieldSettings parse_separation_fields(const YamlCursor& c, double scale) {
  c.only_keys({"degree", "samples_per_axis", "max_deflection"});
  FieldSettings fields;
  if (auto degree = c.find("degree")) fields.degree = separation_count(*degree, 1, 9);
  if (auto samples = c.find("samples_per_axis"))
    fields.samples_per_axis = separation_count(*samples, 1, 50);
  if (fields.samples_per_axis - fields.samples_per_axis % 2 < fields.degree)
    c.fail_message(
        "samples_per_axis must give at least `degree` non-zero samples (an odd count has a zero)");
  if (auto range = c.find("max_deflection"))
    fields.max_deflection = separation_length(*range, scale);
  return fields;
}

void parse_separation_fracture(const YamlCursor& c, double scale, FractureSettings& fracture) {
  c.only_keys({"toughness", "normal_length", "tangential_length", "friction"});
  if (auto v = c.find("toughness"))
    fracture.toughness = v->positive("a positive toughness J_c in J/m^2");
  if (auto v = c.find("normal_length")) fracture.normal_length = separation_length(*v, scale);
  if (auto v = c.find("tangential_length"))
    fracture.tangential_length = separation_length(*v, scale);
  if (auto v = c.find("friction"))
    fracture.friction = v->number_in(0, INFINITY, false, true, "a friction coefficient >= 0");
}

void parse_separation_laser(const YamlCursor& c, double scale, LaserSettings& laser) {
  c.only_keys({"power", "absorbed_fraction", "spot_diameter", "reach"});
  if (auto v = c.find("power")) laser.power = v->positive("a positive power in W");
  if (auto v = c.find("absorbed_fraction"))
    laser.absorbed_fraction = v->number_in(0, 1, true, false, "a fraction in (0, 1]");
  if (auto v = c.find("spot_diameter")) laser.spot_diameter = separation_length(*v, scale);
  if (auto v = c.find("reach")) laser.reach = separation_length(*v, scale);
}

void parse_separation_tissue(const YamlCursor& c, TissueThermal& tissue) {
  c.only_keys({"density", "specific_heat", "temperature_rise", "latent_heat"});
  if (auto v = c.find("density")) tissue.density = v->positive("a positive density in kg/m^3");
  if (auto v = c.find("specific_heat"))
    tissue.specific_heat = v->positive("a positive specific heat in J/(kg K)");
  if (auto v = c.find("temperature_rise"))
    tissue.temperature_rise = v->positive("a positive temperature rise in K");
  if (auto v = c.find("latent_heat"))
    tissue.latent_heat = v->positive("a positive latent heat in J/kg");
}

}  // namespace

SeparationObjectSpec parse_separation_object(const YamlCursor& c, double scale,
                                             const SceneFiles& files) {
  c.only_keys({"name", "model", "layers", "pulled", "base", "interface", "fields", "fracture",
               "laser", "tissue", "force_limit", "instruments", "grasp_reach", "ir_rate_hz",
               "disk_cache"});
  SeparationObjectSpec object;
  if (auto layers = c.find("layers")) {
    for (const char* key : {"pulled", "base", "interface"})
      if (auto own = c.find(key))
        own->fail_message(
            "the generated layers have their own bodies and interface: give "
            "either layers or pulled and base (with an optional interface)");
    object.bodies = parse_separation_layers(*layers, scale);
  } else if (c.find("pulled") || c.find("base")) {
    object.bodies = parse_separation_meshes(c, scale, files);
  } else {
    c.fail("layers (two generated boxes), or pulled and base (each a mesh, material and fixed)");
  }
  if (auto fields = c.find("fields")) object.fields = parse_separation_fields(*fields, scale);
  if (auto fracture = c.find("fracture"))
    parse_separation_fracture(*fracture, scale, object.settings.fracture);
  if (auto laser = c.find("laser")) parse_separation_laser(*laser, scale, object.settings.laser);
  if (auto tissue = c.find("tissue")) parse_separation_tissue(*tissue, object.settings.tissue);
  if (auto limit = c.find("force_limit"))
    object.settings.force_limit = limit->positive("a positive force in N");
  if (auto reach = c.find("grasp_reach")) object.grasp_reach = separation_reach(*reach, scale);
  if (auto instruments = c.find("instruments")) {
    std::set<std::string> tools;
    for (const YamlCursor& item : instruments->items()) {
      item.only_keys({"tool", "laser", "contact", "grasp_reach"});
      SeparationInstrumentSpec instrument;
      instrument.tool = item.at("tool").text();
      if (!tools.insert(instrument.tool).second)
        item.at("tool").fail("a tool not named by an earlier instrument");
      instrument.settings.grasp_reach = object.grasp_reach;
      if (auto laser = item.find("laser")) instrument.settings.laser = laser->boolean();
      if (auto contact = item.find("contact"))
        instrument.settings.contact =
            contact->choice({"grasp", "push"}) == "push" ? ContactMode::push : ContactMode::grasp;
      if (auto reach = item.find("grasp_reach"))
        instrument.settings.grasp_reach = separation_reach(*reach, scale);
      object.instruments.push_back(instrument);
    }
  }
  if (auto rate = c.find("ir_rate_hz")) object.ir_rate_hz = rate->positive("a positive rate in Hz");
  if (auto cache = c.find("disk_cache")) object.disk_cache = cache->boolean();
  try {
    validate(object.settings);
    validate(object.fields);
  } catch (const Error& e) {
    c.fail_message(e.what());
  }
  return object;
}

}  // namespace cohaptic
