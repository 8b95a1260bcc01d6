#include "common/scene/parse_node_selector.h"

#include <cmath>

namespace cohaptic {

NodeSelector parse_node_selector(const YamlCursor& c, double scale) {
  if (!c.is_map()) c.fail("a map with one of surface, box, plane or nodes");
  NodeSelector s;
  s.where = c.location();
  int kinds = 0;
  if (auto surface = c.find("surface")) {
    if (!surface->boolean()) surface->fail("true (select the whole surface)");
    s.kind = NodeSelector::Kind::surface;
    ++kinds;
  }
  if (auto box = c.find("box")) {
    box->only_keys({"min", "max"});
    s.kind = NodeSelector::Kind::box;
    s.box_min = box->at("min").vec3() * scale;
    s.box_max = box->at("max").vec3() * scale;
    if ((s.box_max.array() < s.box_min.array()).any())
      box->at("max").fail("a corner not below min on any axis");
    ++kinds;
  }
  if (auto plane = c.find("plane")) {
    plane->only_keys({"point", "normal", "tolerance"});
    s.kind = NodeSelector::Kind::plane;
    s.plane_point = plane->at("point").vec3() * scale;
    s.plane_normal = plane->at("normal").direction("a non-zero normal vector");
    if (auto tolerance = plane->find("tolerance"))
      s.tolerance = tolerance->number_in(0, INFINITY, true, false, "a positive length") * scale;
    ++kinds;
  }
  if (auto nodes = c.find("nodes")) {
    s.kind = NodeSelector::Kind::node_tags;
    for (const YamlCursor& item : nodes->items()) s.node_tags.push_back(item.integer());
    if (s.node_tags.empty()) nodes->fail("a non-empty list of node ids");
    ++kinds;
  }
  if (kinds != 1) c.fail("exactly one of surface, box, plane or nodes");
  return s;
}

}  // namespace cohaptic
