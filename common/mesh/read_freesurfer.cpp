#include "common/mesh/read_freesurfer.h"

#include <fmt/format.h>

#include <Eigen/Core>
#include <algorithm>
#include <climits>
#include <cstdint>
#include <vector>

#include "common/mesh/mesh_limits.h"
#include "common/util/line_reader.h"

namespace cohaptic {

namespace {

/// Vertices or triangles reserved up front at most, whatever the header claims.
constexpr std::int64_t kMaxReserved = 1 << 20;

/// Moves to the next vertex or triangle line, which must exist and not be blank.
void require_line(LineReader& reader, const char* what, const char* plural, std::int64_t index,
                  std::int64_t count) {
  if (!reader.next())
    reader.fail(fmt::format(
        "the file ends after {} of the {} {} the header announces (line 2): it is truncated "
        "or the header is wrong",
        index, count, plural));
  if (reader.tokens().empty())
    reader.fail(fmt::format("expected a {} line, found an empty line", what));
}

/// Checks that a vertex or triangle line has 3 values plus an optional flag.
void expect_values(const LineReader& reader, const char* what, const char* layout) {
  const std::size_t n = reader.tokens().size();
  if (n != 3 && n != 4)
    reader.fail(
        fmt::format("expected {} '{}', found {} value{}", what, layout, n, n == 1 ? "" : "s"));
  if (n == 4) reader.real(reader.tokens()[3], "flag (4th value)");
}

}  // namespace

TriangleSurface parse_freesurfer_ascii(std::istream& in, const std::string& source_name) {
  LineReader reader(in, source_name);
  if (!reader.next()) reader.fail("empty file: expected a FreeSurfer ASCII surface");
  if (!reader.line().starts_with("#"))
    reader.fail(fmt::format(
        "bad header: a FreeSurfer ASCII surface starts with a comment line '#...', found {}",
        LineReader::quoted(reader.line())));
  if (!reader.next())
    reader.fail("the file ends after the comment line: expected '<vertices> <triangles>'");
  const auto& header = reader.tokens();
  if (header.size() != 2)
    reader.fail(fmt::format("bad header: expected '<vertices> <triangles>', found {}",
                            LineReader::quoted(reader.line())));
  const std::int64_t vertex_count = reader.integer(header[0], "vertex count");
  const std::int64_t triangle_count = reader.integer(header[1], "triangle count");
  if (vertex_count < 3 || triangle_count < 1 || vertex_count > INT_MAX || triangle_count > INT_MAX)
    reader.fail(fmt::format(
        "bad header: a surface needs at least 3 vertices and 1 triangle, found {} and {}",
        vertex_count, triangle_count));
  if (vertex_count > kMaxBodyNodes || triangle_count > 2 * kMaxBodyNodes)
    reader.fail(fmt::format(
        "bad header: {} vertices and {} triangles; a surface may have at most {} vertices and "
        "twice as many triangles",
        vertex_count, triangle_count, kMaxBodyNodes));

  // Storage grows with the lines actually read: the header's counts are only a claim, and
  // a short file claiming billions must fail on its missing lines, not on memory.
  const auto reservation = [](std::int64_t count) {
    return static_cast<std::size_t>(std::min<std::int64_t>(count, kMaxReserved));
  };
  std::vector<double> coordinates;
  coordinates.reserve(3 * reservation(vertex_count));
  for (std::int64_t v = 0; v < vertex_count; ++v) {
    require_line(reader, "vertex", "vertices", v, vertex_count);
    expect_values(reader, "a vertex line", "x y z flag");
    const auto& t = reader.tokens();
    coordinates.push_back(reader.real(t[0], "x coordinate"));
    coordinates.push_back(reader.real(t[1], "y coordinate"));
    coordinates.push_back(reader.real(t[2], "z coordinate"));
  }
  TriangleSurface surface;
  surface.vertices = Eigen::Map<const Eigen::Matrix3Xd>(coordinates.data(), 3,
                                                        static_cast<Eigen::Index>(vertex_count));
  surface.triangles.reserve(reservation(triangle_count));
  for (std::int64_t f = 0; f < triangle_count; ++f) {
    require_line(reader, "triangle", "triangles", f, triangle_count);
    expect_values(reader, "a triangle line", "i j k flag");
    const auto& t = reader.tokens();
    Triangle& triangle = surface.triangles.emplace_back();
    for (int k = 0; k < 3; ++k) {
      const std::int64_t index = reader.integer(t[k], "vertex index");
      if (index < 0 || index >= vertex_count)
        reader.fail(fmt::format(
            "triangle {} refers to vertex index {}, out of range: the file has {} vertices "
            "(0-based indices 0 to {})",
            f, index, vertex_count, vertex_count - 1));
      triangle[k] = static_cast<int>(index);
    }
  }
  while (reader.next())
    if (!reader.tokens().empty())
      reader.fail(fmt::format(
          "unexpected line after the {} vertices and {} triangles the header announces: {}",
          vertex_count, triangle_count, LineReader::quoted(reader.line())));
  return surface;
}

TriangleSurface read_freesurfer_ascii(const std::filesystem::path& path) {
  std::ifstream in = open_text_file(path);
  return parse_freesurfer_ascii(in, path.string());
}

}  // namespace cohaptic
