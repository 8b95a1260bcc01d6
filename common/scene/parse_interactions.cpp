#include "common/scene/parse_interactions.h"

#include <fmt/format.h>

#include <algorithm>
#include <set>

namespace cohaptic {
namespace {

// The object named by the text at `c`; fails naming the known objects when there is none.
const ObjectSpec& named_object(const YamlCursor& c, const std::vector<ObjectSpec>& objects) {
  const std::string name = c.text();
  const auto found = std::find_if(objects.begin(), objects.end(),
                                  [&](const ObjectSpec& o) { return o.name == name; });
  if (found == objects.end()) {
    std::string known;
    for (const ObjectSpec& o : objects) known += (known.empty() ? "" : ", ") + o.name;
    c.fail_message(fmt::format("no object named '{}' (the scene's objects: {})", name, known));
  }
  return *found;
}

}  // namespace

std::vector<InteractionSpec> parse_interactions(const YamlCursor& list,
                                                const std::vector<ObjectSpec>& objects) {
  std::vector<InteractionSpec> interactions;
  std::set<std::string> fronts;
  for (const YamlCursor& item : list.items()) {
    if (!item.is_map()) item.fail("a map {front: OBJECT, behind: OBJECT}");
    item.only_keys({"front", "behind"});
    const YamlCursor front = item.at("front");
    const YamlCursor behind = item.at("behind");
    const ObjectSpec& front_object = named_object(front, objects);
    const ObjectSpec& behind_object = named_object(behind, objects);
    if (&front_object == &behind_object) behind.fail("an object other than the front one");
    if (!std::holds_alternative<MassSpringObjectSpec>(front_object.body) &&
        !std::holds_alternative<ElasticObjectSpec>(front_object.body))
      front.fail_message(fmt::format(
          "object '{}' is neither a mass-spring nor a linear elastic object: only those "
          "front bodies press on another object",
          front_object.name));
    if (!std::holds_alternative<ElasticObjectSpec>(behind_object.body))
      behind.fail_message(fmt::format(
          "object '{}' is not linear elastic: only a condensed linear elastic body can be "
          "the behind object",
          behind_object.name));
    if (!fronts.insert(front_object.name).second)
      front.fail_message(fmt::format("object '{}' is the front of an earlier interaction already",
                                     front_object.name));
    interactions.push_back({front_object.name, behind_object.name, item.location()});
  }
  return interactions;
}

}  // namespace cohaptic
