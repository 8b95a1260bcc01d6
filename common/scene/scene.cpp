#include "common/scene/scene.h"

#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {

const ElasticObjectSpec& single_elastic_object(const Scene& scene) {
  if (scene.objects.size() != 1)
    throw Error(fmt::format("{}: {} objects; this works on a scene with one linear_elastic object",
                            scene.file.string(), scene.objects.size()));
  const auto* spec = std::get_if<ElasticObjectSpec>(&scene.objects.front().body);
  if (!spec)
    throw Error(fmt::format("{}: object '{}' is not linear_elastic", scene.objects.front().where,
                            scene.objects.front().name));
  return *spec;
}

ElasticObjectSpec& single_elastic_object(Scene& scene) {
  return const_cast<ElasticObjectSpec&>(single_elastic_object(static_cast<const Scene&>(scene)));
}

}  // namespace cohaptic
