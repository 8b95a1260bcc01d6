// Mesh file I/O: Gmsh .msh 2.2 / 4.1 reading, .msh 4.1 and .vtu writing, FreeSurfer ASCII
// surfaces. Expectations come from the hand-written files under tests/data/mesh_io, whose
// content is spelled out below, not from the code under test.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "common/mesh/box_mesher.h"
#include "common/mesh/read_freesurfer.h"
#include "common/mesh/read_gmsh.h"
#include "common/mesh/write_gmsh.h"
#include "common/mesh/write_vtu.h"
#include "common/util/error.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string data_file(const std::string& name) {
  return testing::source_path("tests/data/mesh_io/" + name);
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// A fresh directory for one test's output, removed when the test ends.
class ScratchDir {
 public:
  ScratchDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() / ("cohaptic_mesh_io_" + std::to_string(::getpid()) + "_" +
                                         info->test_suite_name() + "_" + info->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// The mesh both two_tets files describe, after the unused nodes 60 and 70 are dropped:
/// nodes 10 20 30 40 50 in that order, tetrahedra 101 = (10 20 30 40), 205 = (20 30 40 50).
void expect_two_tets(const GmshMesh& read) {
  const TetMesh& mesh = read.mesh;
  ASSERT_EQ(mesh.node_count(), 5);
  EXPECT_EQ(mesh.node_tags, (std::vector<std::int64_t>{10, 20, 30, 40, 50}));
  Eigen::Matrix3Xd expected(3, 5);
  expected << 0, 0.1, 0, 0, 0.1,  //
      0, 0, 0.1, 0, 0.1,          //
      0, 0, 0, 0.1, 0.1;
  EXPECT_EQ(mesh.nodes, expected);  // exact: the file's decimal strings parse to these doubles
  ASSERT_EQ(mesh.tet_count(), 2);
  EXPECT_EQ(mesh.tets[0], (Tet{0, 1, 2, 3}));
  EXPECT_EQ(mesh.tets[1], (Tet{1, 2, 3, 4}));
  EXPECT_EQ(mesh.tet_tags, (std::vector<std::int64_t>{101, 205}));
  EXPECT_EQ(read.unused_nodes_dropped, 2);
}

TEST(ReadGmsh, Version22ReadsTetsKeepsTagsAndSkipsTheRest) {
  const GmshMesh read = read_gmsh(data_file("two_tets_v22.msh"));
  expect_two_tets(read);
  EXPECT_EQ(read.skipped_elements, (std::map<int, long>{{1, 1}, {2, 2}, {15, 1}}));
}

TEST(ReadGmsh, Version41ReadsTheSameMeshAndSkipsOtherSections) {
  // $PhysicalNames, $Entities and $NodeData are skipped; the node blocks of the point,
  // surface and volume entities are merged in file order.
  const GmshMesh v41 = read_gmsh(data_file("two_tets_v41.msh"));
  expect_two_tets(v41);
  EXPECT_EQ(v41.skipped_elements, (std::map<int, long>{{1, 1}, {2, 2}, {15, 1}}));

  const GmshMesh v22 = read_gmsh(data_file("two_tets_v22.msh"));
  EXPECT_EQ(v41.mesh.nodes, v22.mesh.nodes);
  EXPECT_EQ(v41.mesh.tets, v22.mesh.tets);
  EXPECT_EQ(v41.mesh.node_tags, v22.mesh.node_tags);
  EXPECT_EQ(v41.mesh.tet_tags, v22.mesh.tet_tags);
}

TEST(ReadGmsh, Version41ParametricNodeBlocksIgnoreUVW) {
  // Blocks on a point (no u), a surface (u v), a curve (u) and a volume (u v w).
  const GmshMesh read = read_gmsh(data_file("two_tets_v41_parametric.msh"));
  expect_two_tets(read);
  EXPECT_EQ(read.skipped_elements, (std::map<int, long>{{2, 1}}));
}

TEST(ReadGmsh, WindowsLineEndingsAndSourceNameInMessages) {
  std::string text = read_text(data_file("two_tets_v22.msh"));
  std::string crlf;
  for (const char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  std::istringstream in(crlf);
  expect_two_tets(parse_gmsh(in, "crlf.msh"));

  std::istringstream bad("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0\n$EndNodes\n");
  try {
    parse_gmsh(bad, "inline.msh");
    FAIL() << "no ParseError";
  } catch (const ParseError& e) {
    EXPECT_THAT(
        e.what(),
        HasSubstr("inline.msh:6: expected a node line 'tag x y z' (4 values), found 3 values"));
    EXPECT_EQ(e.file(), "inline.msh");
    EXPECT_EQ(e.line(), 6);
  }
}

// A mesh larger than any body cohaptic builds fails at the first node past the bound, with
// its line, before more is stored.
TEST(ReadGmsh, MoreNodesThanAnyBodyAreRefusedAtTheFirstOnePast) {
  std::string text = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n300000\n";
  for (int k = 1; k <= 300000; ++k) text += std::to_string(k) + " 0 0 0\n";
  std::istringstream in(text);
  try {
    parse_gmsh(in, "huge.msh");
    FAIL() << "no ParseError";
  } catch (const ParseError& e) {
    EXPECT_THAT(e.what(), HasSubstr("huge.msh:250006: more than 250000 nodes"));
  }
}

TEST(ReadGmsh, MissingFileNamesPathAndReason) {
  const std::string path = data_file("no_such_mesh.msh");
  try {
    read_gmsh(path);
    FAIL() << "no Error";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr(path));
    EXPECT_THAT(e.what(), HasSubstr("No such file or directory"));
  }
}

struct MalformedFile {
  const char* file;
  long line;
  const char* phrase;
};

void PrintTo(const MalformedFile& m, std::ostream* os) { *os << m.file; }

class MalformedMesh : public ::testing::TestWithParam<MalformedFile> {};

TEST_P(MalformedMesh, ThrowsParseErrorAtTheLine) {
  const MalformedFile& m = GetParam();
  const std::string path = data_file(m.file);
  ASSERT_TRUE(fs::exists(path)) << path;
  try {
    if (std::string(m.file).ends_with(".msh"))
      read_gmsh(path);
    else
      read_freesurfer_ascii(path);
    FAIL() << m.file << ": no ParseError";
  } catch (const ParseError& e) {
    EXPECT_THAT(e.what(), HasSubstr(std::string(m.file) + ":" + std::to_string(m.line) + ": "));
    EXPECT_THAT(e.what(), HasSubstr(m.phrase));
    EXPECT_EQ(e.line(), m.line);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Gmsh, MalformedMesh,
    ::testing::Values(
        MalformedFile{
            "bad_binary.msh", 2,
            "binary .msh is not supported; save as ASCII, e.g. gmsh -save -format msh41 -bin 0"},
        MalformedFile{"bad_version.msh", 2,
                      "unsupported .msh version '4.0'; cohaptic reads ASCII versions 2.2 and 4.1"},
        MalformedFile{"bad_missing_format.msh", 1, "missing $MeshFormat"},
        MalformedFile{"bad_truncated.msh", 12, "the file ends inside the $Nodes section"},
        MalformedFile{"bad_unterminated_section.msh", 6,
                      "the file ends inside the $PhysicalNames section"},
        MalformedFile{"bad_node_tag.msh", 9, "expected node tag, found 'abc'"},
        MalformedFile{"bad_coordinate.msh", 8, "expected y coordinate, found '1.0x'"},
        MalformedFile{"bad_nan_coordinate.msh", 7, "non-finite x coordinate 'nan'"},
        MalformedFile{"bad_element_nodes.msh", 14,
                      "element 2 (Gmsh type 4, 4-node tetrahedron) has 3 nodes, expected 4"},
        MalformedFile{"bad_unknown_node.msh", 20, "element 2 refers to node tag 77"},
        MalformedFile{"bad_duplicate_node.msh", 8,
                      "duplicate node tag 3 (first defined on line 7)"},
        MalformedFile{"bad_no_tets.msh", 14, "no 4-node tetrahedra (Gmsh type 4)"},
        MalformedFile{"bad_node_count.msh", 9, "expected $EndNodes after the 3 nodes"}));

INSTANTIATE_TEST_SUITE_P(
    FreeSurfer, MalformedMesh,
    ::testing::Values(
        MalformedFile{"bad_comment.asc", 1, "bad header"},
        MalformedFile{"bad_header.asc", 2, "bad header: expected '<vertices> <triangles>'"},
        MalformedFile{"bad_truncated.asc", 9, "the file ends after 3 of the 4 triangles"},
        MalformedFile{"bad_index.asc", 8, "vertex index 4, out of range"},
        MalformedFile{"bad_number.asc", 5, "expected z coordinate, found 'zero'"},
        MalformedFile{"bad_inf.asc", 6, "non-finite y coordinate 'inf'"}));

// Writers leave "<name>.<pid>.tmp" only while writing; none may survive a call.
bool has_temporary_files(const fs::path& directory) {
  if (!fs::exists(directory)) return false;
  for (const auto& entry : fs::directory_iterator(directory))
    if (entry.path().extension() == ".tmp") return true;
  return false;
}

TetMesh tagged_box_mesh() {
  // Coordinates such as 0.13 / 3 are not short decimals: only 17 digits round-trip them.
  TetMesh mesh = make_box_mesh(Eigen::Vector3d(-0.065, -0.065, -0.13),
                               Eigen::Vector3d::Constant(0.13), Eigen::Vector3i(3, 4, 5));
  mesh.nodes.col(7) = Eigen::Vector3d(1e-300, -0.0, 123456789.123456789);
  for (auto& tag : mesh.node_tags) tag = 7 * tag + 1000000000000;  // sparse, beyond 32 bits
  for (std::size_t t = 0; t < mesh.tet_tags.size(); ++t)
    mesh.tet_tags[t] = static_cast<std::int64_t>(3 * (mesh.tet_tags.size() - t));
  return mesh;
}

TEST(WriteGmsh, RoundTripsBitExactly) {
  const ScratchDir dir;
  const fs::path path = dir.path() / "box.msh";
  for (const TetMesh& mesh : {tagged_box_mesh(), testing::distorted_box_mesh(0.13, 4, 0.3, 17)}) {
    write_gmsh41(path, mesh);
    EXPECT_FALSE(has_temporary_files(path.parent_path()));
    const GmshMesh read = read_gmsh(path);
    EXPECT_EQ(read.unused_nodes_dropped, 0);
    EXPECT_TRUE(read.skipped_elements.empty());
    ASSERT_EQ(read.mesh.node_count(), mesh.node_count());
    EXPECT_EQ(
        std::memcmp(read.mesh.nodes.data(), mesh.nodes.data(), sizeof(double) * mesh.nodes.size()),
        0);
    EXPECT_EQ(read.mesh.tets, mesh.tets);
    EXPECT_EQ(read.mesh.node_tags, mesh.node_tags);
    EXPECT_EQ(read.mesh.tet_tags, mesh.tet_tags);
  }
}

TEST(WriteGmsh, LayoutIsOneNodeBlockAndOneTetBlock) {
  const ScratchDir dir;
  const GmshMesh two = read_gmsh(data_file("two_tets_v41.msh"));
  write_gmsh41(dir.path() / "two.msh", two.mesh);
  EXPECT_EQ(read_text(dir.path() / "two.msh"),
            "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
            "$Nodes\n1 5 10 50\n3 1 0 5\n10\n20\n30\n40\n50\n"
            "0 0 0\n0.10000000000000001 0 0\n0 0.10000000000000001 0\n0 0 0.10000000000000001\n"
            "0.10000000000000001 0.10000000000000001 0.10000000000000001\n$EndNodes\n"
            "$Elements\n1 2 101 205\n3 1 4 2\n101 10 20 30 40\n205 20 30 40 50\n$EndElements\n");
}

TEST(WriteGmsh, RejectsMeshesItCannotWriteFaithfully) {
  const ScratchDir dir;
  TetMesh mesh = tagged_box_mesh();
  mesh.node_tags[5] = mesh.node_tags[4];
  EXPECT_THROW(write_gmsh41(dir.path() / "dup.msh", mesh), Error);
  mesh = tagged_box_mesh();
  mesh.tet_tags[0] = 0;
  EXPECT_THROW(write_gmsh41(dir.path() / "zero.msh", mesh), Error);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(MeshWriters, NonexistentDirectoryThrowsAndLeavesNoFile) {
  const ScratchDir dir;
  const fs::path missing = dir.path() / "no_such_dir";
  const TetMesh mesh = tagged_box_mesh();
  const auto expect_error = [&](const fs::path& path, auto write) {
    try {
      write();
      FAIL() << "no Error for " << path;
    } catch (const Error& e) {
      EXPECT_THAT(e.what(), HasSubstr(path.string()));
      EXPECT_THAT(e.what(), HasSubstr("No such file or directory"));
    }
    EXPECT_FALSE(fs::exists(path));
    EXPECT_FALSE(has_temporary_files(path.parent_path()));
  };
  expect_error(missing / "box.msh", [&] { write_gmsh41(missing / "box.msh", mesh); });
  expect_error(missing / "box.vtu", [&] { write_vtu(missing / "box.vtu", mesh, {}); });
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(MeshWriters, FailedRenameLeavesNoTemporaryFile) {
  // The target is a directory: the rename fails, the temporary file is removed.
  const ScratchDir dir;
  const fs::path target = dir.path() / "taken.msh";
  fs::create_directory(target);
  EXPECT_THROW(write_gmsh41(target, tagged_box_mesh()), Error);
  EXPECT_TRUE(fs::is_directory(target));
  EXPECT_FALSE(has_temporary_files(target.parent_path()));
}

// --- a tiny reader for the .vtu files write_vtu writes (ASCII DataArrays only) ---

std::string attribute(const std::string& xml, const std::string& element, const std::string& name) {
  const std::regex pattern("<" + element + "\\b[^>]*\\b" + name + "=\"([^\"]*)\"");
  std::smatch match;
  if (!std::regex_search(xml, match, pattern)) return "";
  return match[1];
}

/// The opening tag and the whitespace-separated values of the DataArray named `name`.
std::pair<std::string, std::vector<std::string>> data_array(const std::string& xml,
                                                            const std::string& name) {
  const std::regex pattern("(<DataArray\\b[^>]*\\bName=\"" + name + "\"[^>]*>)([^<]*)</DataArray>");
  std::smatch match;
  if (!std::regex_search(xml, match, pattern)) return {};
  std::istringstream values(match[2].str());
  std::vector<std::string> tokens;
  for (std::string token; values >> token;) tokens.push_back(token);
  return {match[1].str(), tokens};
}

template <typename T>
std::vector<T> numbers(const std::vector<std::string>& tokens) {
  std::vector<T> out;
  for (const std::string& token : tokens) {
    T value{};
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    EXPECT_TRUE(ec == std::errc() && end == token.data() + token.size()) << token;
    out.push_back(value);
  }
  return out;
}

TEST(WriteVtu, ParsesBackWithExactValues) {
  const ScratchDir dir;
  const TetMesh mesh = tagged_box_mesh();
  const int n = mesh.node_count();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(-1e-3, 1e-3);
  Eigen::MatrixXd displacement(3, n), stress(1, n);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) displacement(k, i) = uniform(rng);
    stress(0, i) = uniform(rng) * 1e9;
  }
  displacement(0, 1) = 1e-310;  // subnormal
  const fs::path path = dir.path() / "box.vtu";
  write_vtu(path, mesh, {{"displacement", displacement}, {"von Mises <Pa>", stress}});
  EXPECT_FALSE(has_temporary_files(path.parent_path()));
  const std::string xml = read_text(path);

  EXPECT_EQ(attribute(xml, "VTKFile", "type"), "UnstructuredGrid");
  EXPECT_EQ(attribute(xml, "Piece", "NumberOfPoints"), std::to_string(n));
  EXPECT_EQ(attribute(xml, "Piece", "NumberOfCells"), std::to_string(mesh.tet_count()));

  const auto points = data_array(xml, "Points");
  EXPECT_THAT(points.first, HasSubstr("NumberOfComponents=\"3\""));
  const auto xyz = numbers<double>(points.second);
  ASSERT_EQ(xyz.size(), 3u * n);
  EXPECT_EQ(std::memcmp(xyz.data(), mesh.nodes.data(), sizeof(double) * xyz.size()), 0);

  const auto connectivity = numbers<std::int64_t>(data_array(xml, "connectivity").second);
  const auto offsets = numbers<std::int64_t>(data_array(xml, "offsets").second);
  const auto types = numbers<int>(data_array(xml, "types").second);
  ASSERT_EQ(connectivity.size(), 4u * mesh.tet_count());
  ASSERT_EQ(offsets.size(), static_cast<std::size_t>(mesh.tet_count()));
  ASSERT_EQ(types.size(), static_cast<std::size_t>(mesh.tet_count()));
  for (int t = 0; t < mesh.tet_count(); ++t) {
    for (int k = 0; k < 4; ++k) EXPECT_EQ(connectivity[4 * t + k], mesh.tets[t][k]);
    EXPECT_EQ(offsets[t], 4 * (t + 1));
    EXPECT_EQ(types[t], 10);
  }

  const auto displacement_array = data_array(xml, "displacement");
  EXPECT_THAT(displacement_array.first, HasSubstr("type=\"Float64\""));
  EXPECT_THAT(displacement_array.first, HasSubstr("NumberOfComponents=\"3\""));
  const auto u = numbers<double>(displacement_array.second);
  ASSERT_EQ(u.size(), 3u * n);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(u[3 * i + k], displacement(k, i)) << "node " << i;

  const auto stress_array = data_array(xml, "von Mises &lt;Pa&gt;");
  EXPECT_THAT(stress_array.first, HasSubstr("NumberOfComponents=\"1\""));
  const auto s = numbers<double>(stress_array.second);
  ASSERT_EQ(s.size(), static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) EXPECT_EQ(s[i], stress(0, i));

  const auto node_tag = data_array(xml, "node_tag");
  EXPECT_THAT(node_tag.first, HasSubstr("type=\"Int64\""));
  EXPECT_EQ(numbers<std::int64_t>(node_tag.second), mesh.node_tags);
  const auto element_tag = data_array(xml, "element_tag");
  EXPECT_THAT(element_tag.first, HasSubstr("type=\"Int64\""));
  EXPECT_EQ(numbers<std::int64_t>(element_tag.second), mesh.tet_tags);
  // element_tag is cell data, node_tag point data.
  EXPECT_LT(xml.find("<CellData"), xml.find("Name=\"element_tag\""));
  EXPECT_LT(xml.find("Name=\"node_tag\""), xml.find("</PointData>"));
}

TEST(WriteVtu, FieldWithWrongNodeCountThrowsNamingIt) {
  const ScratchDir dir;
  const TetMesh mesh = tagged_box_mesh();
  const fs::path path = dir.path() / "bad.vtu";
  try {
    write_vtu(path, mesh, {{"displacement", Eigen::MatrixXd::Zero(3, mesh.node_count() - 1)}});
    FAIL() << "no Error";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("'displacement'"));
    EXPECT_THAT(e.what(), HasSubstr(std::to_string(mesh.node_count() - 1) + " columns"));
  }
  EXPECT_THROW(write_vtu(path, mesh, {{"node_tag", Eigen::MatrixXd::Zero(1, mesh.node_count())}}),
               Error);
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

// 47 bytes claiming 1.8e9 vertices would ask for 42 GB: a claim beyond the largest body is
// refused at the header, and within it storage is not sized by the header: the missing
// lines are the error.
TEST(ReadFreeSurfer, AHeaderClaimingBillionsOfVerticesIsRefusedAndStorageFollowsTheLines) {
  const auto error_of = [](const std::string& text) {
    std::istringstream in(text);
    try {
      parse_freesurfer_ascii(in, "claims.asc");
    } catch (const ParseError& e) {
      return std::string(e.what());
    }
    return std::string("no ParseError");
  };
  EXPECT_THAT(error_of("#!ascii\n1772764997 4\n0 0 0 0\n"),
              HasSubstr("claims.asc:2: bad header: 1772764997 vertices and 4 triangles; a surface "
                        "may have at most "
                        "250000 vertices"));
  EXPECT_THAT(error_of("#!ascii\n250000 4\n0 0 0 0\n"),
              HasSubstr("claims.asc:3: the file ends after 1 of the 250000 vertices"));
}

TEST(ReadFreeSurfer, TetrahedronSurface) {
  const TriangleSurface surface = read_freesurfer_ascii(data_file("tet_surface.asc"));
  Eigen::Matrix3Xd expected(3, 4);
  expected << 0, 10.5, 0, -1.25,  //
      0, 0, 10.5, 2,              //
      0, 0, 0, 10.5;
  EXPECT_EQ(surface.vertices, expected);
  EXPECT_EQ(surface.triangles, (std::vector<Triangle>{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}));
}

TEST(ReadFreeSurfer, Colin27BrainSurface) {
  const std::string path = testing::source_path("../shared/data/colin27/brain_surface.asc");
  if (!fs::exists(path))
    GTEST_SKIP() << path << " is not present (shared/ is not beside this clone)";
  const TriangleSurface surface = read_freesurfer_ascii(path);
  ASSERT_EQ(surface.vertex_count(), 10242);
  ASSERT_EQ(surface.triangle_count(), 20480);
  // First vertex and triangle as written in the file.
  EXPECT_EQ(surface.vertices.col(0), Eigen::Vector3d(-1.793828, -1.990235, 70.536179));
  EXPECT_EQ(surface.triangles[0], (Triangle{0, 2564, 2562}));
  // A closed surface: every edge is shared by exactly two triangles, and V - E + F = 2.
  std::map<std::pair<int, int>, int> edges;
  for (const Triangle& tri : surface.triangles)
    for (int k = 0; k < 3; ++k) ++edges[std::minmax(tri[k], tri[(k + 1) % 3])];
  for (const auto& [edge, count] : edges) ASSERT_EQ(count, 2) << edge.first << "-" << edge.second;
  EXPECT_EQ(surface.vertex_count() - static_cast<int>(edges.size()) + surface.triangle_count(), 2);
}

}  // namespace
}  // namespace cohaptic
