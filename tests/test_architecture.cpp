// The one-way rule of the layout (docs/layout.md, "Layout"), read from the sources: every
// `#include "..."` of common/, proto/, net/, view/, server/, client/ and lab/ is resolved to
// the directory (the floor) it comes from, and each floor may include only the floors listed
// for it: server/ and client/ never include each other or lab/, net/ and view/ no program's
// directory (the server and the lab both use the view), common/ nothing outside common/. Each
// subdirectory of common/ may include only those listed for it (kCommonMayInclude, a list that
// must itself have no cycle, so common/ never includes itself in a circle); a failure names the
// file and line. The link-level twin of this test is cmake/check_links.cmake.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace cohaptic {
namespace {

namespace fs = std::filesystem;

const fs::path kSourceDir = COHAPTIC_SOURCE_DIR;

// What each floor may include, itself included.
const std::map<std::string, std::set<std::string>> kMayInclude = {
    {"common", {"common"}},
    {"proto", {"proto", "common"}},
    {"net", {"net", "proto", "common"}},
    {"view", {"view", "net", "proto", "common"}},
    {"server", {"server", "view", "net", "proto", "common"}},
    {"client", {"client", "net", "proto", "common"}},
    {"lab", {"lab", "view", "net", "proto", "common"}},
};

// What each subdirectory of common/ may include besides itself. The bodies' physics (fem,
// mass_spring, separation, laparoscopy) stands on mesh, contact and condense; the scene
// describes the bodies, the model compiles a scene, the IR is built from the model, and the
// simulation (sim) drives them all. `kinds` (vocabularies and limits every floor shares)
// and `util` include nothing of ours, so any floor may use them: the IR's types and the
// haptic loop's evaluator take the contact model from kinds/, not from the scene.
const std::map<std::string, std::set<std::string>> kCommonMayInclude = {
    {"condense", {"fem", "util"}},
    {"contact", {"condense", "fem", "mesh", "util"}},
    {"delay", {"util"}},
    {"fem", {"mesh", "util"}},
    {"haptics", {"util"}},
    {"interaction", {"fem", "mass_spring", "mesh", "model", "util"}},
    {"ir",
     {"condense", "contact", "fem", "kinds", "laparoscopy", "mass_spring", "mesh", "model",
      "separation", "util"}},
    {"kinds", {}},
    {"laparoscopy", {"contact", "mesh", "util"}},
    {"mass_spring", {"contact", "fem", "mesh", "util"}},
    {"mesh", {"util"}},
    {"model",
     {"contact", "fem", "kinds", "laparoscopy", "mass_spring", "mesh", "scene", "separation",
      "util"}},
    {"scene", {"fem", "kinds", "laparoscopy", "mass_spring", "mesh", "separation", "util"}},
    {"separation", {"contact", "fem", "mesh", "study", "util"}},
    {"sim",
     {"condense", "contact", "fem", "interaction", "ir", "kinds", "laparoscopy", "mass_spring",
      "model", "scene", "util"}},
    {"study", {"util"}},
    {"sync", {"util"}},
    {"util", {}},
};

struct Include {
  fs::path file;  ///< relative to the source directory
  int line = 0;
  fs::path included;  ///< relative to the source directory, as resolved
  std::string where() const {
    return file.string() + ":" + std::to_string(line) + " includes " + included.string();
  }
};

// An include of ours resolved to a path from the source directory: relative to the
// including file when it exists there (e.g. "../server/x.h"), else from the source
// directory. protoc's headers ("cohaptic/messages.pb.h") come from proto/cohaptic/.
fs::path resolve(const fs::path& file, const std::string& text) {
  const fs::path beside = (kSourceDir / file).parent_path() / text;
  if (fs::exists(beside))
    return fs::relative(fs::weakly_canonical(beside), fs::weakly_canonical(kSourceDir));
  if (text.rfind("cohaptic/", 0) == 0) return fs::path("proto") / text;
  return fs::path(text).lexically_normal();
}

std::string floor_of(const fs::path& path) {
  return path.begin() == path.end() ? "" : path.begin()->string();
}

// The quoted includes of every C++ source and header under the floor `floor`.
std::vector<Include> quoted_includes(const std::string& floor) {
  static const std::regex include_line(R"re(^\s*#\s*include\s*"([^"]+)")re");
  std::vector<Include> includes;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(kSourceDir / floor)) {
    const std::string extension = entry.path().extension().string();
    if (!entry.is_regular_file() ||
        (extension != ".h" && extension != ".cpp" && extension != ".hpp"))
      continue;
    const fs::path file = fs::relative(entry.path(), kSourceDir);
    std::ifstream in(entry.path());
    std::string text;
    std::smatch match;
    for (int line = 1; std::getline(in, text); ++line)
      if (std::regex_search(text, match, include_line))
        includes.push_back({file, line, resolve(file, match[1].str())});
  }
  return includes;
}

// A directed graph of directory names, each edge with one include that makes it.
using IncludeGraph = std::map<std::string, std::map<std::string, Include>>;

// A cycle as the nodes along it, the first repeated at the end; nothing if there is none.
std::optional<std::vector<std::string>> find_cycle(const IncludeGraph& graph) {
  enum class Mark { unvisited, on_path, done };
  std::map<std::string, Mark> mark;
  std::vector<std::string> path;
  std::optional<std::vector<std::string>> cycle;
  const auto visit = [&](const auto& self, const std::string& node) -> void {
    mark[node] = Mark::on_path;
    path.push_back(node);
    if (const auto edges = graph.find(node); edges != graph.end())
      for (const auto& [next, evidence] : edges->second) {
        if (cycle) return;
        if (mark[next] == Mark::on_path) {
          cycle = std::vector<std::string>(std::find(path.begin(), path.end(), next), path.end());
          cycle->push_back(next);
          return;
        }
        if (mark[next] == Mark::unvisited) self(self, next);
      }
    path.pop_back();
    mark[node] = Mark::done;
  };
  for (const auto& [node, edges] : graph)
    if (!cycle && mark[node] == Mark::unvisited) visit(visit, node);
  return cycle;
}

std::string describe_cycle(const IncludeGraph& graph, const std::vector<std::string>& cycle) {
  std::string text;
  for (std::size_t i = 0; i < cycle.size(); ++i) text += (i ? " -> " : "") + cycle[i];
  for (std::size_t i = 0; i + 1 < cycle.size(); ++i)
    text += "\n  " + graph.at(cycle[i]).at(cycle[i + 1]).where();
  return text;
}

TEST(Architecture, TheCycleFinderFindsACycleAndOnlyACycle) {
  const auto edge = [](const std::string& from, const std::string& to) {
    return Include{fs::path(from) / "x.h", 1, fs::path(to) / "y.h"};
  };
  IncludeGraph graph;
  graph["a"]["b"] = edge("a", "b");
  graph["b"]["c"] = edge("b", "c");
  graph["a"]["c"] = edge("a", "c");
  graph["d"]["a"] = edge("d", "a");
  EXPECT_FALSE(find_cycle(graph)) << "a diamond with a tail is not a cycle";
  graph["c"]["a"] = edge("c", "a");
  const auto cycle = find_cycle(graph);
  ASSERT_TRUE(cycle);
  ASSERT_GE(cycle->size(), 3u);
  EXPECT_EQ(cycle->front(), cycle->back());
  for (std::size_t i = 0; i + 1 < cycle->size(); ++i)
    EXPECT_TRUE(graph.count((*cycle)[i]) && graph.at((*cycle)[i]).count((*cycle)[i + 1]))
        << "not an edge";
  EXPECT_NE(describe_cycle(graph, *cycle).find("x.h:1 includes"), std::string::npos);
}

TEST(Architecture, EachFloorIncludesOnlyTheFloorsItMayUse) {
  std::size_t checked = 0;
  for (const auto& [floor, allowed] : kMayInclude) {
    ASSERT_TRUE(fs::is_directory(kSourceDir / floor)) << floor;
    for (const Include& include : quoted_includes(floor)) {
      const std::string target = floor_of(include.included);
      if (!kMayInclude.count(target)) continue;  // not ours (a quoted third-party header)
      ++checked;
      if (!allowed.count(target))
        ADD_FAILURE() << include.where() << ": " << floor << "/ may not include " << target << "/";
    }
  }
  EXPECT_GT(checked, 500u) << "the walk found too few includes to be reading the sources";
}

// common/X/... -> "X"; nothing for a file directly in common/.
std::optional<std::string> common_subdirectory(const fs::path& path) {
  const std::vector<fs::path> parts(path.begin(), path.end());
  if (parts.size() < 3 || parts[0] != "common") return std::nullopt;
  return parts[1].string();
}

// The includes between common/'s subdirectories, one include as the evidence of each edge.
IncludeGraph common_include_graph() {
  IncludeGraph graph;
  for (const Include& include : quoted_includes("common")) {
    const auto from = common_subdirectory(include.file), to = common_subdirectory(include.included);
    if (from && to && *from != *to) graph[*from].try_emplace(*to, include);
  }
  return graph;
}

// The includes lie within an acyclic list, so common/ never includes itself in a circle.
TEST(Architecture, CommonsSubdirectoriesIncludeOnlyWhatTheirListAllows) {
  IncludeGraph allowed;
  for (const auto& [from, targets] : kCommonMayInclude)
    for (const std::string& to : targets)
      allowed[from][to] = Include{fs::path("common") / from, 0, fs::path("common") / to};
  if (const auto cycle = find_cycle(allowed))
    ADD_FAILURE() << "the allowed list itself has a cycle: " << describe_cycle(allowed, *cycle);

  for (const fs::directory_entry& entry : fs::directory_iterator(kSourceDir / "common")) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() && !kCommonMayInclude.count(name))
      ADD_FAILURE() << "common/" << name
                    << "/ is not in kCommonMayInclude: say what it may include";
  }
  const IncludeGraph graph = common_include_graph();
  EXPECT_GE(graph.size(), 10u) << "the walk found too few subdirectories of common/";
  std::size_t edges = 0;
  for (const auto& [from, targets] : graph)
    for (const auto& [to, evidence] : targets) {
      ++edges;
      const auto listed = kCommonMayInclude.find(from);
      if (listed == kCommonMayInclude.end() || !listed->second.count(to))
        ADD_FAILURE() << evidence.where() << ": common/" << from << "/ may not include common/"
                      << to << "/";
    }
  EXPECT_GE(edges, 30u) << "the walk found too few includes between common/'s subdirectories";
}

TEST(Architecture, NoFileCitesAPlanOutsideTheRepository) {
  // The project documents itself (docs/architecture.md); a comment pointing at a plan a
  // clone does not have is a dead end for its reader.
  const std::string outside = std::string("DESIGN") + ".md";
  std::vector<std::string> citations;
  for (const char* floor : {"common", "proto", "net", "server", "client", "lab", "tests", "docs",
                            "scenes", "deploy", "cmake"}) {
    if (!fs::exists(kSourceDir / floor)) continue;
    for (const fs::directory_entry& entry : fs::recursive_directory_iterator(kSourceDir / floor)) {
      if (!entry.is_regular_file() || entry.file_size() > 1'000'000) continue;
      std::ifstream in(entry.path());
      std::string text;
      for (int line = 1; std::getline(in, text); ++line)
        if (text.find(outside) != std::string::npos)
          citations.push_back(fs::relative(entry.path(), kSourceDir).string() + ":" +
                              std::to_string(line));
    }
  }
  for (const char* file : {"README.md", "CMakeLists.txt", "Makefile"}) {
    std::ifstream in(kSourceDir / file);
    std::string text;
    for (int line = 1; std::getline(in, text); ++line)
      if (text.find(outside) != std::string::npos)
        citations.push_back(std::string(file) + ":" + std::to_string(line));
  }
  EXPECT_TRUE(citations.empty()) << "cite docs/architecture.md instead at: "
                                 << ::testing::PrintToString(citations);
}

}  // namespace
}  // namespace cohaptic
