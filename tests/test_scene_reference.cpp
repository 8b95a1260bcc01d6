// docs/scene-reference.md documents every key the scene parser accepts, and no other:
//   - the parser's keys are the string literals of every only_keys({...}) call in
//     common/scene/*.cpp (a call may span lines), and of every find("...") and at("...")
//     there (so that a key read without such a list is counted too);
//   - the page's keys are its key tables' rows: a key table is a Markdown table whose header's
//     first cell is `key`; each of its rows starts with one backticked key path in the first
//     cell (`objects[].material.poisson_ratio`), and the row documents the path's last
//     component (`poisson_ratio`; a trailing [] is dropped, as in `objects[]`).
// A key is documented when it is some row's last component, so a key the parser gains fails
// EveryKeyTheParserAcceptsIsDocumented, and a key it loses fails
// EveryDocumentedKeyIsOneTheParserAccepts. And each map is one table:
// EveryCheckedMapHasATableOfExactlyItsKeys pairs every only_keys call with a table whose
// keys are exactly the call's, every table with such a call, and checks that a table's rows
// share one parent path, a key documented on the page (or the top level).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace scene_reference_test {

namespace fs = std::filesystem;

const fs::path kSourceRoot = COHAPTIC_SOURCE_DIR;
const fs::path kReferencePage = "docs/scene-reference.md";

std::string file_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

int line_at(const std::string& text, std::size_t offset) {
  return 1 + static_cast<int>(std::count(text.begin(),
                                         text.begin() + static_cast<std::ptrdiff_t>(offset), '\n'));
}

// One only_keys({...}) call: where it is and the keys it accepts.
struct KeyList {
  std::string where;  // common/scene/<file>.cpp:<line>
  std::set<std::string> keys;
};

struct ParserKeys {
  std::vector<KeyList> lists;
  std::map<std::string, std::set<std::string>> files_of_key;  // key -> the files that accept it
};

ParserKeys parser_keys() {
  ParserKeys parsed;
  std::vector<fs::path> sources;
  for (const auto& entry : fs::directory_iterator(kSourceRoot / "common/scene"))
    if (entry.is_regular_file() && entry.path().extension() == ".cpp")
      sources.push_back(entry.path());
  std::sort(sources.begin(), sources.end());

  static const std::regex kLiteral("\"([^\"\\\\]*)\"");
  static const std::regex kRead(R"re((?:\.|->)(?:find|at)\("([A-Za-z_][A-Za-z0-9_]*)"\))re");
  const std::string call = "only_keys(";
  for (const fs::path& source : sources) {
    const std::string text = file_text(source);
    const std::string file = fs::relative(source, kSourceRoot).generic_string();
    for (std::size_t at = text.find(call); at != std::string::npos;
         at = text.find(call, at + call.size())) {
      std::size_t open = at + call.size();
      while (open < text.size() && std::isspace(static_cast<unsigned char>(text[open]))) ++open;
      if (open >= text.size() || text[open] != '{') continue;  // the declaration, or a mention
      const std::size_t close = text.find('}', open);
      if (close == std::string::npos) continue;
      const std::string braces = text.substr(open, close - open);
      KeyList list{file + ":" + std::to_string(line_at(text, at)), {}};
      for (std::sregex_iterator m(braces.begin(), braces.end(), kLiteral), end; m != end; ++m) {
        list.keys.insert((*m)[1].str());
        parsed.files_of_key[(*m)[1].str()].insert(file);
      }
      parsed.lists.push_back(std::move(list));
    }
    for (std::sregex_iterator m(text.begin(), text.end(), kRead), end; m != end; ++m)
      parsed.files_of_key[(*m)[1].str()].insert(file);
  }
  return parsed;
}

// One row of a key table on the page.
struct Row {
  int line = 0;
  std::string path;  // as written, e.g. objects[].mesh.box.min
  std::string key;   // its last component, e.g. min
};

struct KeyTable {
  std::string heading;
  int line = 0;  // of the header
  std::vector<Row> rows;
};

struct Page {
  std::vector<KeyTable> tables;
  std::vector<std::string> malformed;  // rows of key tables without one backticked key path first
};

// The first cell of a Markdown table row ("| a | b |" -> "a"), escaped pipes kept.
std::string first_cell(const std::string& line) {
  std::string cell;
  for (std::size_t i = 1; i < line.size(); ++i) {
    if (line[i] == '\\' && i + 1 < line.size()) {
      cell += line.substr(i, 2);
      ++i;
      continue;
    }
    if (line[i] == '|') break;
    cell += line[i];
  }
  const auto first = cell.find_first_not_of(' ');
  const auto last = cell.find_last_not_of(' ');
  return first == std::string::npos ? std::string() : cell.substr(first, last - first + 1);
}

// "objects[].mesh.box.min" -> "min"; "objects[]" -> "objects"; "" when it is no key path.
std::string last_component(std::string path) {
  static const std::regex kPath(R"(^[a-z_][a-z0-9_]*(\[\])?(\.[a-z_][a-z0-9_]*(\[\])?)*$)");
  if (!std::regex_match(path, kPath)) return {};
  if (path.size() >= 2 && path.compare(path.size() - 2, 2, "[]") == 0) path.resize(path.size() - 2);
  const auto dot = path.rfind('.');
  return dot == std::string::npos ? path : path.substr(dot + 1);
}

// "objects[].mesh.box.min" -> "objects[].mesh.box"; "name" -> "".
std::string parent_path(const std::string& path) {
  const auto dot = path.rfind('.');
  return dot == std::string::npos ? std::string() : path.substr(0, dot);
}

std::string without_list_mark(std::string path) {
  if (path.size() >= 2 && path.compare(path.size() - 2, 2, "[]") == 0) path.resize(path.size() - 2);
  return path;
}

Page reference_page() {
  Page page;
  std::istringstream in(file_text(kSourceRoot / kReferencePage));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  static const std::regex kBackticked("^`([^`]+)`$");
  std::string heading;
  bool fenced = false;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    if (line.rfind("```", 0) == 0) fenced = !fenced;
    if (fenced) continue;
    if (line.rfind('#', 0) == 0) heading = line;
    if (line.rfind('|', 0) != 0 || first_cell(line) != "key") continue;
    KeyTable table{heading, static_cast<int>(i + 1), {}};
    std::size_t r = i + 2;  // past the header and its |---| line
    for (; r < lines.size() && lines[r].rfind('|', 0) == 0; ++r) {
      const std::string cell = first_cell(lines[r]);
      const std::string where = kReferencePage.generic_string() + ":" + std::to_string(r + 1);
      std::smatch match;
      std::string key;
      if (std::regex_match(cell, match, kBackticked)) key = last_component(match[1].str());
      if (key.empty()) {
        page.malformed.push_back(where + ": " + lines[r]);
        continue;
      }
      table.rows.push_back({static_cast<int>(r + 1), match[1].str(), key});
    }
    page.tables.push_back(std::move(table));
    i = r - 1;
  }
  return page;
}

std::set<std::string> keys_of(const KeyTable& table) {
  std::set<std::string> keys;
  for (const Row& row : table.rows) keys.insert(row.key);
  return keys;
}

std::string joined(const std::set<std::string>& keys) {
  std::string text;
  for (const std::string& key : keys) text += (text.empty() ? "" : ", ") + key;
  return text;
}

TEST(SceneReference, EveryKeyTheParserAcceptsIsDocumented) {
  const ParserKeys parser = parser_keys();
  const Page page = reference_page();
  // The extraction must be reading the parser: dozens of maps, over a hundred keys.
  ASSERT_GE(parser.lists.size(), 30u) << "found too few only_keys calls in common/scene/*.cpp";
  ASSERT_GE(parser.files_of_key.size(), 100u) << "found too few keys in common/scene/*.cpp";
  ASSERT_FALSE(page.tables.empty()) << kReferencePage.generic_string() << " has no key table";

  std::set<std::string> documented;
  for (const KeyTable& table : page.tables)
    for (const Row& row : table.rows) documented.insert(row.key);
  std::string missing;
  int count = 0;
  for (const auto& [key, files] : parser.files_of_key)
    if (!documented.count(key)) {
      ++count;
      std::string where;
      for (const std::string& file : files) where += (where.empty() ? "" : ", ") + file;
      missing += "\n  " + key + " (accepted in " + where + ")";
    }
  EXPECT_EQ(count, 0) << count
                      << " key(s) the scene parser accepts are not documented in a key table of "
                      << kReferencePage.generic_string()
                      << " (a row whose first cell is the key's path in backticks):" << missing;
}

TEST(SceneReference, EveryDocumentedKeyIsOneTheParserAccepts) {
  const ParserKeys parser = parser_keys();
  const Page page = reference_page();
  std::string unknown;
  int count = 0;
  for (const KeyTable& table : page.tables)
    for (const Row& row : table.rows)
      if (!parser.files_of_key.count(row.key)) {
        ++count;
        unknown += "\n  " + kReferencePage.generic_string() + ":" + std::to_string(row.line) +
                   ": `" + row.path + "` (" + row.key + ")";
      }
  EXPECT_EQ(count, 0)
      << count << " documented key(s) that the scene parser (common/scene/*.cpp) does not accept:"
      << unknown;
  std::string malformed;
  for (const std::string& row : page.malformed) malformed += "\n  " + row;
  EXPECT_TRUE(page.malformed.empty())
      << "key-table rows whose first cell is not one backticked key path:" << malformed;
}

TEST(SceneReference, EveryCheckedMapHasATableOfExactlyItsKeys) {
  const ParserKeys parser = parser_keys();
  const Page page = reference_page();

  std::string problems;
  for (const KeyList& list : parser.lists) {
    const bool tabled =
        std::any_of(page.tables.begin(), page.tables.end(),
                    [&](const KeyTable& table) { return keys_of(table) == list.keys; });
    if (!tabled)
      problems +=
          "\n  " + list.where + ": no table has exactly the keys {" + joined(list.keys) + "}";
  }

  std::set<std::string> paths;
  for (const KeyTable& table : page.tables)
    for (const Row& row : table.rows) paths.insert(without_list_mark(row.path));
  for (const KeyTable& table : page.tables) {
    const std::string where = kReferencePage.generic_string() + ":" + std::to_string(table.line) +
                              " (" + table.heading + ")";
    const std::set<std::string> keys = keys_of(table);
    const bool parsed = std::any_of(parser.lists.begin(), parser.lists.end(),
                                    [&](const KeyList& list) { return list.keys == keys; });
    if (!parsed)
      problems += "\n  " + where + ": no only_keys call accepts exactly {" + joined(keys) + "}";
    if (table.rows.empty()) continue;
    const std::string parent = parent_path(table.rows.front().path);
    for (const Row& row : table.rows)
      if (parent_path(row.path) != parent)
        problems += "\n  " + kReferencePage.generic_string() + ":" + std::to_string(row.line) +
                    ": `" + row.path + "` is not under `" + parent + "` like the table's first row";
    if (!parent.empty() && !paths.count(without_list_mark(parent)))
      problems += "\n  " + where + ": its parent `" + parent + "` is documented in no table";
  }
  EXPECT_TRUE(problems.empty()) << "the page's key tables and the parser's only_keys calls differ:"
                                << problems;
}

}  // namespace scene_reference_test
