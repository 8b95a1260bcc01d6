#include "common/mesh/read_gmsh.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <span>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "common/mesh/mesh_limits.h"
#include "common/util/error.h"
#include "common/util/line_reader.h"

namespace cohaptic {

namespace {

constexpr int kTetrahedron = 4;

struct ElementType {
  int type;
  int nodes;
  const char* name;
};

constexpr ElementType kElementTypes[] = {
    {1, 2, "2-node line"},        {2, 3, "3-node triangle"},       {3, 4, "4-node quadrangle"},
    {4, 4, "4-node tetrahedron"}, {5, 8, "8-node hexahedron"},     {6, 6, "6-node prism"},
    {7, 5, "5-node pyramid"},     {8, 3, "3-node line"},           {9, 6, "6-node triangle"},
    {10, 9, "9-node quadrangle"}, {11, 10, "10-node tetrahedron"}, {12, 27, "27-node hexahedron"},
    {13, 18, "18-node prism"},    {14, 14, "14-node pyramid"},     {15, 1, "1-node point"},
    {16, 8, "8-node quadrangle"}, {17, 20, "20-node hexahedron"},  {18, 15, "15-node prism"},
    {19, 13, "13-node pyramid"},
};

/// Node count of a Gmsh element type, or -1 if cohaptic does not know the type.
int element_node_count(int type) {
  for (const ElementType& t : kElementTypes)
    if (t.type == type) return t.nodes;
  return -1;
}

struct RawTet {
  std::array<std::int64_t, 4> node_tags;
  std::int64_t tag;
  long line;
};

class GmshParser {
 public:
  GmshParser(std::istream& in, const std::string& source_name) : reader_(in, source_name) {}
  GmshMesh parse();

 private:
  void read_format();
  void read_nodes_v2();
  void read_nodes_v4();
  void read_elements_v2();
  void read_elements_v4();
  void skip_section(std::string_view name);
  void require_line(std::string_view section, std::string_view what);
  void expect_end(std::string_view section, std::string_view after);
  void expect_token_count(std::size_t count, std::string_view what);
  std::int64_t count(std::string_view token, std::string_view field) const;
  std::int64_t node_tag(std::string_view token) const;
  std::int64_t element_tag(std::string_view token) const;
  int element_type(std::string_view token) const;
  void add_node(std::int64_t tag, double x, double y, double z);
  void add_element(int type, std::int64_t tag, std::span<const std::string_view> nodes);
  GmshMesh finish();

  LineReader reader_;
  int major_version_ = 0;
  std::vector<double> coordinates_;  // x y z per node, in file order
  std::vector<std::int64_t> node_tags_;
  std::unordered_map<std::int64_t, int> node_index_;
  std::vector<long> node_lines_;
  std::vector<RawTet> tets_;
  std::unordered_map<std::int64_t, long> tet_tag_lines_;
  std::map<int, long> skipped_;
  long nodes_line_ = 0;
  long elements_line_ = 0;
};

GmshMesh GmshParser::parse() {
  if (!reader_.next_nonblank())
    reader_.fail("empty file: missing $MeshFormat (is this a Gmsh .msh file?)");
  if (reader_.tokens()[0] != "$MeshFormat")
    reader_.fail(fmt::format("missing $MeshFormat: a Gmsh .msh file starts with it, found {}",
                             LineReader::quoted(reader_.line())));
  read_format();
  while (reader_.next_nonblank()) {
    const std::string_view first = reader_.tokens()[0];
    if (first.front() != '$') continue;  // text between sections is ignored, as Gmsh does
    const std::string_view name = first.substr(1);
    if (name == "MeshFormat") reader_.fail("a second $MeshFormat section");
    if (name.starts_with("End"))
      reader_.fail(fmt::format("{} without a section to end", LineReader::quoted(first)));
    if (name == "Nodes") {
      if (nodes_line_ != 0)
        reader_.fail(
            fmt::format("a second $Nodes section (the first is on line {}); only one is supported",
                        nodes_line_));
      nodes_line_ = reader_.line_number();
      major_version_ == 2 ? read_nodes_v2() : read_nodes_v4();
    } else if (name == "Elements") {
      if (elements_line_ != 0)
        reader_.fail(fmt::format(
            "a second $Elements section (the first is on line {}); only one is supported",
            elements_line_));
      elements_line_ = reader_.line_number();
      major_version_ == 2 ? read_elements_v2() : read_elements_v4();
    } else {
      skip_section(name);
    }
  }
  return finish();
}

void GmshParser::read_format() {
  require_line("MeshFormat", "the format line 'version file-type data-size'");
  const auto& tokens = reader_.tokens();
  if (tokens.size() >= 2 && tokens[1] != "0") {
    if (tokens[1] == "1")
      reader_.fail(
          "binary .msh is not supported; save as ASCII, e.g. gmsh -save -format msh41 -bin 0");
    reader_.fail(fmt::format("expected file type 0 (ASCII) in $MeshFormat, found {}",
                             LineReader::quoted(tokens[1])));
  }
  expect_token_count(3, "the format line 'version file-type data-size'");
  const double version = reader_.real(tokens[0], "format version");
  const long tenths = std::lround(version * 10);
  if (tenths == 41 && std::abs(version - 4.1) < 1e-9) {
    major_version_ = 4;
  } else if (tenths >= 20 && tenths <= 22 &&
             std::abs(version * 10 - static_cast<double>(tenths)) < 1e-9) {
    major_version_ = 2;  // 2.0 and 2.1 share the layout of 2.2
  } else {
    reader_.fail(
        fmt::format("unsupported .msh version {}; cohaptic reads ASCII versions 2.2 and 4.1 "
                    "(convert, e.g. gmsh file.msh -save -format msh41 -bin 0 -o out.msh)",
                    LineReader::quoted(tokens[0])));
  }
  reader_.integer(tokens[2], "data size");
  expect_end("MeshFormat", "the format line");
}

void GmshParser::require_line(std::string_view section, std::string_view what) {
  if (!reader_.next_nonblank())
    reader_.fail(fmt::format(
        "the file ends inside the ${} section while expecting {}: it is truncated (no $End{})",
        section, what, section));
  const std::string_view first = reader_.tokens()[0];
  if (first.front() == '$')
    reader_.fail(fmt::format("the ${} section ends early: expected {}, found {}", section, what,
                             LineReader::quoted(first)));
}

void GmshParser::expect_end(std::string_view section, std::string_view after) {
  if (!reader_.next_nonblank())
    reader_.fail(fmt::format("the file ends inside the ${} section: it is truncated (no $End{})",
                             section, section));
  if (reader_.tokens()[0] != fmt::format("$End{}", section))
    reader_.fail(fmt::format("expected $End{} after {}, found {}", section, after,
                             LineReader::quoted(reader_.line())));
}

void GmshParser::expect_token_count(std::size_t expected, std::string_view what) {
  const std::size_t found = reader_.tokens().size();
  if (found != expected)
    reader_.fail(fmt::format("expected {} ({} value{}), found {} value{}", what, expected,
                             expected == 1 ? "" : "s", found, found == 1 ? "" : "s"));
}

std::int64_t GmshParser::count(std::string_view token, std::string_view field) const {
  const std::int64_t value = reader_.integer(token, field);
  if (value < 0) reader_.fail(fmt::format("{} must not be negative, found {}", field, value));
  return value;
}

std::int64_t GmshParser::node_tag(std::string_view token) const {
  const std::int64_t tag = reader_.integer(token, "node tag");
  if (tag <= 0) reader_.fail(fmt::format("node tag must be positive, found {}", tag));
  return tag;
}

std::int64_t GmshParser::element_tag(std::string_view token) const {
  const std::int64_t tag = reader_.integer(token, "element tag");
  if (tag <= 0) reader_.fail(fmt::format("element tag must be positive, found {}", tag));
  return tag;
}

int GmshParser::element_type(std::string_view token) const {
  const std::int64_t type = reader_.integer(token, "element type");
  if (type <= 0 || type > INT_MAX)
    reader_.fail(fmt::format("element type must be a positive integer, found {}", type));
  return static_cast<int>(type);
}

void GmshParser::add_node(std::int64_t tag, double x, double y, double z) {
  const auto [it, inserted] = node_index_.emplace(tag, static_cast<int>(node_tags_.size()));
  if (!inserted)
    reader_.fail(fmt::format("duplicate node tag {} (first defined on line {})", tag,
                             node_lines_[it->second]));
  if (node_tags_.size() >= static_cast<std::size_t>(kMaxBodyNodes))
    reader_.fail(
        fmt::format("more than {} nodes: larger than any body cohaptic builds", kMaxBodyNodes));
  node_tags_.push_back(tag);
  node_lines_.push_back(reader_.line_number());
  coordinates_.insert(coordinates_.end(), {x, y, z});
}

void GmshParser::add_element(int type, std::int64_t tag, std::span<const std::string_view> nodes) {
  const int expected = element_node_count(type);
  if (expected >= 0 && static_cast<int>(nodes.size()) != expected)
    reader_.fail(fmt::format("element {} (Gmsh type {}, {}) has {} node{}, expected {}", tag, type,
                             gmsh_element_type_name(type), nodes.size(),
                             nodes.size() == 1 ? "" : "s", expected));
  if (type != kTetrahedron) {
    ++skipped_[type];
    return;
  }
  RawTet tet{};
  for (int i = 0; i < 4; ++i) tet.node_tags[i] = node_tag(nodes[i]);
  tet.tag = tag;
  tet.line = reader_.line_number();
  const auto [it, inserted] = tet_tag_lines_.emplace(tag, tet.line);
  if (!inserted)
    reader_.fail(fmt::format("duplicate element tag {} (first used on line {})", tag, it->second));
  if (tets_.size() >= static_cast<std::size_t>(kMaxBodyTetrahedra))
    reader_.fail(fmt::format("more than {} tetrahedra: larger than any body cohaptic builds",
                             kMaxBodyTetrahedra));
  tets_.push_back(tet);
}

void GmshParser::read_nodes_v2() {
  require_line("Nodes", "the number of nodes");
  expect_token_count(1, "the number of nodes");
  const std::int64_t total = count(reader_.tokens()[0], "number of nodes");
  for (std::int64_t i = 0; i < total; ++i) {
    require_line("Nodes", "a node line 'tag x y z'");
    expect_token_count(4, "a node line 'tag x y z'");
    const auto& t = reader_.tokens();
    add_node(node_tag(t[0]), reader_.real(t[1], "x coordinate"), reader_.real(t[2], "y coordinate"),
             reader_.real(t[3], "z coordinate"));
  }
  expect_end("Nodes", fmt::format("the {} nodes announced on line {}", total, nodes_line_ + 1));
}

void GmshParser::read_nodes_v4() {
  constexpr std::string_view kHeader =
      "the $Nodes header 'numEntityBlocks numNodes minNodeTag maxNodeTag'";
  require_line("Nodes", kHeader);
  expect_token_count(4, kHeader);
  const long header_line = reader_.line_number();
  const std::int64_t blocks = count(reader_.tokens()[0], "number of node blocks");
  const std::int64_t total = count(reader_.tokens()[1], "number of nodes");
  reader_.integer(reader_.tokens()[2], "minimum node tag");
  reader_.integer(reader_.tokens()[3], "maximum node tag");
  std::int64_t found = 0;
  std::vector<std::int64_t> tags;
  for (std::int64_t b = 0; b < blocks; ++b) {
    constexpr std::string_view kBlock =
        "a node block header 'entityDim entityTag parametric numNodesInBlock'";
    require_line("Nodes", kBlock);
    expect_token_count(4, kBlock);
    const auto& t = reader_.tokens();
    const std::int64_t dim = reader_.integer(t[0], "entity dimension");
    if (dim < 0 || dim > 3)
      reader_.fail(fmt::format("entity dimension must be 0 to 3, found {}", dim));
    reader_.integer(t[1], "entity tag");
    const std::int64_t parametric = reader_.integer(t[2], "parametric flag");
    if (parametric != 0 && parametric != 1)
      reader_.fail(fmt::format("parametric flag must be 0 or 1, found {}", parametric));
    const std::int64_t in_block = count(t[3], "number of nodes in block");
    // MSH 4.1 lists a block's tags first, one per line, then its coordinates, one node per
    // line; a parametric block adds u (dim >= 1), v (dim >= 2), w (dim 3) after x y z.
    tags.clear();
    for (std::int64_t i = 0; i < in_block; ++i) {
      require_line("Nodes", "a node tag");
      if (reader_.tokens().size() != 1)
        reader_.fail(fmt::format(
            "expected a node tag alone on its line (MSH 4.1 lists a block's tags, then its "
            "coordinates), found {} values",
            reader_.tokens().size()));
      tags.push_back(node_tag(reader_.tokens()[0]));
    }
    const std::size_t values = 3 + static_cast<std::size_t>(parametric != 0 ? dim : 0);
    const std::string_view kNames[] = {"x y z", "x y z u", "x y z u v", "x y z u v w"};
    for (std::int64_t i = 0; i < in_block; ++i) {
      require_line("Nodes", "node coordinates");
      const auto& c = reader_.tokens();
      if (c.size() != values)
        reader_.fail(fmt::format("expected the coordinates '{}' of node {}, found {} value{}",
                                 kNames[values - 3], tags[i], c.size(), c.size() == 1 ? "" : "s"));
      for (std::size_t k = 3; k < values; ++k) reader_.real(c[k], "parametric coordinate");
      add_node(tags[i], reader_.real(c[0], "x coordinate"), reader_.real(c[1], "y coordinate"),
               reader_.real(c[2], "z coordinate"));
    }
    found += in_block;
  }
  if (found != total)
    reader_.fail_at(header_line,
                    fmt::format("the $Nodes header announces {} nodes but its {} block{} hold {}",
                                total, blocks, blocks == 1 ? "" : "s", found));
  expect_end("Nodes", fmt::format("the {} node block{} announced on line {}", blocks,
                                  blocks == 1 ? "" : "s", header_line));
}

void GmshParser::read_elements_v2() {
  require_line("Elements", "the number of elements");
  expect_token_count(1, "the number of elements");
  const std::int64_t total = count(reader_.tokens()[0], "number of elements");
  for (std::int64_t i = 0; i < total; ++i) {
    constexpr std::string_view kLine = "an element line 'tag type number-of-tags tags... nodes...'";
    require_line("Elements", kLine);
    const auto& t = reader_.tokens();
    if (t.size() < 3) expect_token_count(3, kLine);
    const std::int64_t tag = element_tag(t[0]);
    const int type = element_type(t[1]);
    const std::int64_t tag_count = count(t[2], "number of tags");
    if (tag_count > static_cast<std::int64_t>(t.size()) - 3)
      reader_.fail(
          fmt::format("element {} announces {} tags but its line has only {} values after the type",
                      tag, tag_count, t.size() - 2));
    for (std::size_t k = 3; k < 3 + static_cast<std::size_t>(tag_count); ++k)
      reader_.integer(t[k], "element tag value");
    add_element(
        type, tag,
        std::span<const std::string_view>(t).subspan(3 + static_cast<std::size_t>(tag_count)));
  }
  expect_end("Elements",
             fmt::format("the {} elements announced on line {}", total, elements_line_ + 1));
}

void GmshParser::read_elements_v4() {
  constexpr std::string_view kHeader =
      "the $Elements header 'numEntityBlocks numElements minElementTag maxElementTag'";
  require_line("Elements", kHeader);
  expect_token_count(4, kHeader);
  const long header_line = reader_.line_number();
  const std::int64_t blocks = count(reader_.tokens()[0], "number of element blocks");
  const std::int64_t total = count(reader_.tokens()[1], "number of elements");
  reader_.integer(reader_.tokens()[2], "minimum element tag");
  reader_.integer(reader_.tokens()[3], "maximum element tag");
  std::int64_t found = 0;
  for (std::int64_t b = 0; b < blocks; ++b) {
    constexpr std::string_view kBlock =
        "an element block header 'entityDim entityTag elementType numElementsInBlock'";
    require_line("Elements", kBlock);
    expect_token_count(4, kBlock);
    const auto& t = reader_.tokens();
    reader_.integer(t[0], "entity dimension");
    reader_.integer(t[1], "entity tag");
    const int type = element_type(t[2]);
    const std::int64_t in_block = count(t[3], "number of elements in block");
    for (std::int64_t i = 0; i < in_block; ++i) {
      require_line("Elements", "an element line 'tag node-tags...'");
      const auto& e = reader_.tokens();
      add_element(type, element_tag(e[0]), std::span<const std::string_view>(e).subspan(1));
    }
    found += in_block;
  }
  if (found != total)
    reader_.fail_at(
        header_line,
        fmt::format("the $Elements header announces {} elements but its {} block{} hold {}", total,
                    blocks, blocks == 1 ? "" : "s", found));
  expect_end("Elements", fmt::format("the {} element block{} announced on line {}", blocks,
                                     blocks == 1 ? "" : "s", header_line));
}

void GmshParser::skip_section(std::string_view line_name) {
  const std::string name(line_name);  // line_name points into the line about to be replaced
  const std::string end = "$End" + name;
  while (reader_.next())
    if (!reader_.tokens().empty() && reader_.tokens()[0] == end) return;
  reader_.fail(
      fmt::format("the file ends inside the ${} section: it is truncated (no {})", name, end));
}

GmshMesh GmshParser::finish() {
  if (elements_line_ == 0)
    reader_.fail(
        "no $Elements section: the file has no tetrahedra (mesh the volume, e.g. gmsh -3, and save "
        "again)");
  if (tets_.empty()) {
    std::string found;
    for (const auto& [type, n] : skipped_)
      found += fmt::format("{}{} of type {} ({})", found.empty() ? "" : ", ", n, type,
                           gmsh_element_type_name(type));
    reader_.fail_at(
        elements_line_,
        fmt::format("no 4-node tetrahedra (Gmsh type 4) in $Elements{}; mesh the volume "
                    "(e.g. gmsh -3) and save again",
                    found.empty() ? std::string(", which is empty") : ", only " + found));
  }
  const int file_nodes = static_cast<int>(node_tags_.size());
  std::vector<int> new_index(file_nodes, -1);
  std::vector<Tet> tets(tets_.size());
  for (std::size_t t = 0; t < tets_.size(); ++t) {
    for (int i = 0; i < 4; ++i) {
      const std::int64_t tag = tets_[t].node_tags[i];
      const auto it = node_index_.find(tag);
      if (it == node_index_.end())
        reader_.fail_at(
            tets_[t].line,
            nodes_line_ == 0
                ? fmt::format(
                      "element {} refers to node tag {}, but the file has no $Nodes section",
                      tets_[t].tag, tag)
                : fmt::format(
                      "element {} refers to node tag {}, which $Nodes (line {}) does not define",
                      tets_[t].tag, tag, nodes_line_));
      tets[t][i] = it->second;
      new_index[it->second] = 0;
    }
  }
  int used = 0;
  for (int& index : new_index)
    if (index == 0) index = used++;

  GmshMesh result;
  TetMesh& mesh = result.mesh;
  mesh.nodes.resize(3, used);
  mesh.node_tags.resize(used);
  for (int n = 0; n < file_nodes; ++n) {
    if (new_index[n] < 0) continue;
    for (int k = 0; k < 3; ++k) mesh.nodes(k, new_index[n]) = coordinates_[3 * n + k];
    mesh.node_tags[new_index[n]] = node_tags_[n];
  }
  for (Tet& tet : tets)
    for (int& node : tet) node = new_index[node];
  mesh.tets = std::move(tets);
  mesh.tet_tags.reserve(tets_.size());
  for (const RawTet& tet : tets_) mesh.tet_tags.push_back(tet.tag);
  result.skipped_elements = skipped_;
  result.unused_nodes_dropped = file_nodes - used;

  const std::string& source = reader_.source_name();
  for (const auto& [type, n] : skipped_)
    spdlog::info("{}: skipped {} element{} of Gmsh type {} ({}); only 4-node tetrahedra are used",
                 source, n, n == 1 ? "" : "s", type, gmsh_element_type_name(type));
  if (result.unused_nodes_dropped > 0)
    spdlog::info("{}: dropped {} node{} that no tetrahedron uses", source,
                 result.unused_nodes_dropped, result.unused_nodes_dropped == 1 ? "" : "s");
  return result;
}

}  // namespace

std::string gmsh_element_type_name(int type) {
  for (const ElementType& t : kElementTypes)
    if (t.type == type) return t.name;
  return "unknown type";
}

GmshMesh parse_gmsh(std::istream& in, const std::string& source_name) {
  return GmshParser(in, source_name).parse();
}

GmshMesh read_gmsh(const std::filesystem::path& path) {
  std::ifstream in = open_text_file(path);
  return parse_gmsh(in, path.string());
}

}  // namespace cohaptic
