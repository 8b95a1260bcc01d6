#include "common/mesh/write_gmsh.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "common/util/atomic_file.h"
#include "common/util/error.h"

namespace cohaptic {

namespace {

/// Tags to write for `count` items: `tags` as given, or index + 1 when it is empty.
std::vector<std::int64_t> checked_tags(const std::filesystem::path& path,
                                       const std::vector<std::int64_t>& tags, int count,
                                       std::string_view what) {
  if (tags.empty()) {
    std::vector<std::int64_t> generated(static_cast<std::size_t>(count));
    for (int i = 0; i < count; ++i) generated[i] = i + 1;
    return generated;
  }
  if (static_cast<int>(tags.size()) != count)
    throw Error(fmt::format("cannot write {}: the mesh has {} {}s but {} {} tags", path.string(),
                            count, what, tags.size(), what));
  std::unordered_set<std::int64_t> seen;
  seen.reserve(tags.size());
  for (const std::int64_t tag : tags) {
    if (tag <= 0)
      throw Error(fmt::format("cannot write {}: {} tag {} is not positive, which Gmsh requires",
                              path.string(), what, tag));
    if (!seen.insert(tag).second)
      throw Error(
          fmt::format("cannot write {}: {} tag {} is used twice", path.string(), what, tag));
  }
  return tags;
}

}  // namespace

void write_gmsh41(const std::filesystem::path& path, const TetMesh& mesh) {
  const int node_count = mesh.node_count();
  const int tet_count = mesh.tet_count();
  if (tet_count == 0)
    throw Error(fmt::format("cannot write {}: the mesh has no tetrahedra", path.string()));
  const std::vector<std::int64_t> node_tags =
      checked_tags(path, mesh.node_tags, node_count, "node");
  const std::vector<std::int64_t> tet_tags =
      checked_tags(path, mesh.tet_tags, tet_count, "element");
  for (int n = 0; n < node_count; ++n)
    if (!mesh.nodes.col(n).allFinite())
      throw Error(fmt::format("cannot write {}: node {} has a non-finite coordinate", path.string(),
                              node_tags[n]));
  for (int t = 0; t < tet_count; ++t)
    for (const int node : mesh.tets[t])
      if (node < 0 || node >= node_count)
        throw Error(fmt::format(
            "cannot write {}: element {} refers to node index {}, but the mesh has {} nodes",
            path.string(), tet_tags[t], node, node_count));

  AtomicFile file(path);
  file.write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
  file.print("$Nodes\n1 {} {} {}\n", node_count,
             *std::min_element(node_tags.begin(), node_tags.end()),
             *std::max_element(node_tags.begin(), node_tags.end()));
  file.print("3 1 0 {}\n", node_count);
  for (const std::int64_t tag : node_tags) file.print("{}\n", tag);
  for (int n = 0; n < node_count; ++n)
    file.print("{:.17g} {:.17g} {:.17g}\n", mesh.nodes(0, n), mesh.nodes(1, n), mesh.nodes(2, n));
  file.write("$EndNodes\n");
  file.print("$Elements\n1 {} {} {}\n", tet_count,
             *std::min_element(tet_tags.begin(), tet_tags.end()),
             *std::max_element(tet_tags.begin(), tet_tags.end()));
  file.print("3 1 4 {}\n", tet_count);
  for (int t = 0; t < tet_count; ++t) {
    const Tet& tet = mesh.tets[t];
    file.print("{} {} {} {} {}\n", tet_tags[t], node_tags[tet[0]], node_tags[tet[1]],
               node_tags[tet[2]], node_tags[tet[3]]);
  }
  file.write("$EndElements\n");
  file.commit();
}

}  // namespace cohaptic
