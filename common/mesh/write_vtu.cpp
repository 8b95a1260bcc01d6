#include "common/mesh/write_vtu.h"

#include <fmt/format.h>

#include <array>
#include <cstdint>
#include <set>
#include <string_view>

#include "common/util/atomic_file.h"
#include "common/util/error.h"

namespace cohaptic {

namespace {

constexpr int kVtkTriangle = 5;
constexpr int kVtkTetra = 10;

/// Text safe inside a double-quoted XML attribute.
std::string xml_escaped(std::string_view text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

/// The tag of item i: tags[i], or i + 1 when the mesh has no tags.
std::int64_t tag_of(const std::vector<std::int64_t>& tags, int i) {
  return tags.empty() ? i + 1 : tags[i];
}

template <std::size_t N>
void check_input(const std::filesystem::path& path, const Eigen::Matrix3Xd& points,
                 const std::vector<std::array<int, N>>& cells,
                 const std::vector<std::int64_t>& point_tags,
                 const std::vector<std::int64_t>& cell_tags,
                 const std::vector<VtuPointField>& point_fields) {
  const std::string file = path.string();
  const auto node_count = static_cast<int>(points.cols());
  if (!point_tags.empty() && static_cast<int>(point_tags.size()) != node_count)
    throw Error(fmt::format("cannot write {}: the mesh has {} nodes but {} node tags", file,
                            node_count, point_tags.size()));
  if (!cell_tags.empty() && cell_tags.size() != cells.size())
    throw Error(fmt::format("cannot write {}: the mesh has {} elements but {} element tags", file,
                            cells.size(), cell_tags.size()));
  for (int n = 0; n < node_count; ++n)
    if (!points.col(n).allFinite())
      throw Error(fmt::format("cannot write {}: node {} has a non-finite coordinate", file,
                              tag_of(point_tags, n)));
  for (std::size_t t = 0; t < cells.size(); ++t)
    for (const int node : cells[t])
      if (node < 0 || node >= node_count)
        throw Error(fmt::format(
            "cannot write {}: element {} refers to node index {}, but the mesh has {} nodes", file,
            tag_of(cell_tags, static_cast<int>(t)), node, node_count));
  std::set<std::string, std::less<>> names = {"node_tag"};
  for (const VtuPointField& field : point_fields) {
    if (field.name.empty())
      throw Error(fmt::format("cannot write {}: a point field has no name", file));
    if (!names.insert(field.name).second)
      throw Error(
          fmt::format("cannot write {}: point field name '{}' is {}", file, field.name,
                      field.name == "node_tag" ? "reserved for the node tags" : "used twice"));
    if (field.values.cols() != node_count)
      throw Error(
          fmt::format("cannot write {}: point field '{}' has {} columns, but the mesh has {} nodes",
                      file, field.name, field.values.cols(), node_count));
    if (field.values.rows() < 1)
      throw Error(fmt::format("cannot write {}: point field '{}' has no components (0 rows)", file,
                              field.name));
    for (int n = 0; n < node_count; ++n)
      if (!field.values.col(n).allFinite())
        throw Error(fmt::format("cannot write {}: point field '{}' is not finite at node {}", file,
                                field.name, tag_of(point_tags, n)));
  }
}

void write_doubles(AtomicFile& file, const Eigen::Ref<const Eigen::MatrixXd>& values) {
  for (Eigen::Index c = 0; c < values.cols(); ++c) {
    file.print("          {:.17g}", values(0, c));
    for (Eigen::Index r = 1; r < values.rows(); ++r) file.print(" {:.17g}", values(r, c));
    file.write("\n");
  }
}

// An UnstructuredGrid of cells of one kind (N nodes each, VTK type `vtk_type`).
template <std::size_t N>
void write_grid(const std::filesystem::path& path, const Eigen::Matrix3Xd& points,
                const std::vector<std::array<int, N>>& cells, int vtk_type,
                const std::vector<std::int64_t>& point_tags,
                const std::vector<std::int64_t>& cell_tags,
                const std::vector<VtuPointField>& point_fields) {
  check_input(path, points, cells, point_tags, cell_tags, point_fields);
  const auto node_count = static_cast<int>(points.cols());
  const auto tet_count = static_cast<int>(cells.size());

  // The first scalar and the first vector field become ParaView's active ones.
  std::string active;
  for (const int components : {1, 3})
    for (const VtuPointField& field : point_fields)
      if (field.values.rows() == components) {
        active += fmt::format(" {}=\"{}\"", components == 1 ? "Scalars" : "Vectors",
                              xml_escaped(field.name));
        break;
      }

  AtomicFile file(path);
  file.write("<?xml version=\"1.0\"?>\n");
  file.write(
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n");
  file.write("  <UnstructuredGrid>\n");
  file.print("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", node_count, tet_count);

  file.print("      <PointData{}>\n", active);
  for (const VtuPointField& field : point_fields) {
    file.print(
        "        <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" "
        "format=\"ascii\">\n",
        xml_escaped(field.name), field.values.rows());
    write_doubles(file, field.values);
    file.write("        </DataArray>\n");
  }
  file.write("        <DataArray type=\"Int64\" Name=\"node_tag\" format=\"ascii\">\n");
  for (int n = 0; n < node_count; ++n) file.print("          {}\n", tag_of(point_tags, n));
  file.write("        </DataArray>\n");
  file.write("      </PointData>\n");

  file.write("      <CellData Scalars=\"element_tag\">\n");
  file.write("        <DataArray type=\"Int64\" Name=\"element_tag\" format=\"ascii\">\n");
  for (int t = 0; t < tet_count; ++t) file.print("          {}\n", tag_of(cell_tags, t));
  file.write("        </DataArray>\n");
  file.write("      </CellData>\n");

  file.write("      <Points>\n");
  file.write(
      "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" "
      "format=\"ascii\">\n");
  write_doubles(file, points);
  file.write("        </DataArray>\n");
  file.write("      </Points>\n");

  file.write("      <Cells>\n");
  file.write("        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
  for (const auto& cell : cells) {
    file.write("         ");
    for (const int node : cell) file.print(" {}", node);
    file.write("\n");
  }
  file.write("        </DataArray>\n");
  file.write("        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
  for (int t = 0; t < tet_count; ++t)
    file.print("          {}\n", static_cast<std::int64_t>(N) * (t + 1));
  file.write("        </DataArray>\n");
  file.write("        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
  for (int t = 0; t < tet_count; ++t) file.print("          {}\n", vtk_type);
  file.write("        </DataArray>\n");
  file.write("      </Cells>\n");

  file.write("    </Piece>\n");
  file.write("  </UnstructuredGrid>\n");
  file.write("</VTKFile>\n");
  file.commit();
}

}  // namespace

void write_vtu(const std::filesystem::path& path, const TetMesh& mesh,
               const std::vector<VtuPointField>& point_fields) {
  write_grid(path, mesh.nodes, mesh.tets, kVtkTetra, mesh.node_tags, mesh.tet_tags, point_fields);
}

void write_surface_vtu(const std::filesystem::path& path, const Eigen::Matrix3Xd& vertices,
                       const std::vector<Triangle>& triangles,
                       const std::vector<std::int64_t>& vertex_tags,
                       const std::vector<VtuPointField>& point_fields) {
  write_grid(path, vertices, triangles, kVtkTriangle, vertex_tags, {}, point_fields);
}

}  // namespace cohaptic
