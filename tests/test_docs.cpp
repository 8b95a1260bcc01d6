// The manual's references hold, read from the tree as a reader would follow them:
//   - every page a file cites as docs/<page>.md exists, with the heading it names after it
//     in quotes (`docs/studies.md "Study files"`) or as an anchor (docs/<page>.md#<anchor>);
//   - every heading cited on the README (README and the heading in quotes) is one of its headings;
//   - every relative Markdown link of a page lands on a file, and on a heading of it when it
//     names an anchor.
// Every page of docs/results/ says which command writes it, is stamped, and is made again by
// `make results`.
// And the tree describes what is built, not how it came to be: no line dates itself by a
// numbered stage of the project's development, names another engineer's build or speaks of
// the code as it was before a change (what changed and when goes in CHANGELOG.md, the one
// file left out, with this one, which spells the patterns).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace cohaptic {
namespace {

namespace fs = std::filesystem;
const fs::path kTreeRoot = COHAPTIC_SOURCE_DIR;

// The project's own text files: generated, vendored and built trees left out.
bool skipped_directory(const fs::path& relative) {
  static const std::set<std::string> kSkippedPaths = {"out", "view/web/lib", "tests/fuzz/corpus"};
  const std::string name = relative.filename().string();
  return kSkippedPaths.count(relative.generic_string()) > 0 || name == ".git" ||
         name == "node_modules" || name.rfind("build", 0) == 0;
}

struct TextFile {
  fs::path relative;
  std::vector<std::string> lines;
};

std::vector<TextFile> project_text_files() {
  std::vector<TextFile> files;
  for (auto it = fs::recursive_directory_iterator(kTreeRoot);
       it != fs::recursive_directory_iterator(); ++it) {
    const fs::path relative = fs::relative(it->path(), kTreeRoot);
    if (it->is_directory()) {
      if (skipped_directory(relative)) it.disable_recursion_pending();
      continue;
    }
    if (!it->is_regular_file() || it->file_size() > 1'000'000) continue;
    std::ifstream in(it->path(), std::ios::binary);
    std::stringstream buffer;
    buffer << in.rdbuf();
    const std::string text = buffer.str();
    if (text.find('\0') != std::string::npos) continue;  // binary
    TextFile file{relative, {}};
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) file.lines.push_back(line);
    files.push_back(std::move(file));
  }
  return files;
}

// GitHub's anchor for a heading: lower case, spaces to hyphens, punctuation dropped (ASCII
// and the common Unicode dashes, quotes, arrows and operators); letters and digits of any
// script kept.
std::string anchor_of(const std::string& heading) {
  std::string anchor;
  for (std::size_t i = 0; i < heading.size();) {
    const auto byte = static_cast<unsigned char>(heading[i]);
    if (byte < 0x80) {
      if (std::isalnum(byte) || byte == '-' || byte == '_')
        anchor += static_cast<char>(std::tolower(byte));
      else if (byte == ' ')
        anchor += '-';
      ++i;
      continue;
    }
    const std::size_t length = byte >= 0xF0 ? 4 : byte >= 0xE0 ? 3 : 2;
    const std::string sequence = heading.substr(i, length);
    char32_t code = length == 2 ? (byte & 0x1Fu) : length == 3 ? (byte & 0x0Fu) : (byte & 0x07u);
    for (std::size_t k = 1; k < sequence.size(); ++k)
      code = (code << 6) | (static_cast<unsigned char>(sequence[k]) & 0x3Fu);
    const bool latin_symbol = code >= 0xA1 && code <= 0xBF && code != 0xB2 && code != 0xB3 &&
                              code != 0xB5 && code != 0xB9;
    const bool punctuation = (code >= 0x2000 && code <= 0x206F) ||
                             (code >= 0x2190 && code <= 0x22FF) || code == 0xD7 || code == 0xF7 ||
                             latin_symbol;
    if (!punctuation) anchor += sequence;
    i += length;
  }
  return anchor;
}

struct Headings {
  std::set<std::string> texts, anchors;
};

// The headings of a Markdown file (ATX headings outside fenced code).
const Headings& headings_of(const fs::path& page) {
  static std::map<fs::path, Headings> cache;
  if (const auto found = cache.find(page); found != cache.end()) return found->second;
  Headings headings;
  std::ifstream in(page);
  static const std::regex kHeading(R"(^#{1,6}\s+(.*?)\s*#*\s*$)");
  bool fenced = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("```", 0) == 0) fenced = !fenced;
    std::smatch match;
    if (fenced || !std::regex_match(line, match, kHeading)) continue;
    headings.texts.insert(match[1]);
    headings.anchors.insert(anchor_of(match[1]));
  }
  return cache.emplace(page, std::move(headings)).first->second;
}

std::string line_at(const TextFile& file, std::size_t index) {
  return file.relative.generic_string() + ":" + std::to_string(index + 1);
}

// Line `index` of a file as the sentence before it reads on: without its comment marker
// (`//`, `#`, `*`) and the blanks around it; empty past the end.
std::string continued_text(const TextFile& file, std::size_t index) {
  if (index >= file.lines.size()) return "";
  static const std::regex kCommentMarker(R"(^\s*(//+|#+|\*+)?\s*)");
  return std::regex_replace(file.lines[index], kCommentMarker, "",
                            std::regex_constants::format_first_only);
}

TEST(Docs, AnchorsAreGitHubsForHeadingsWithCodePunctuationAndDashes) {
  EXPECT_EQ(anchor_of("Study files"), "study-files");
  EXPECT_EQ(anchor_of("`cohaptic-lab probe`"), "cohaptic-lab-probe");
  EXPECT_EQ(anchor_of("Objects that press on each other (`common/interaction/`)"),
            "objects-that-press-on-each-other-commoninteraction");
  EXPECT_EQ(anchor_of("Paired comparisons (Scheffé's method, Nakaya's modification)"),
            "paired-comparisons-scheffés-method-nakayas-modification");
  EXPECT_EQ(anchor_of("Speed – accuracy → trade"), "speed--accuracy--trade");
}

TEST(Docs, EveryCitedPageHeadingAndLinkExists) {
  static const std::regex kPageCitation(
      R"re((?:^|[^\w/.-])(docs/[\w/.-]+?\.md)(?:,? "([^"]+)"|#([\w-]+))?)re");
  static const std::regex kReadmeCitation(
      R"re((?:^|[^\w/.-])README(?:\.md)?(?:'s)?,? "([^"]+)")re");
  static const std::regex kMarkdownLink(R"(\]\(([^)\s]+)\))");
  std::size_t citations = 0;
  std::vector<std::string> broken;
  const auto check_heading = [&](const fs::path& page, const std::string& text,
                                 const std::string& anchor, const std::string& at) {
    const Headings& headings = headings_of(page);
    if (!text.empty() && !headings.texts.count(text))
      broken.push_back(at + ": no heading \"" + text + "\" on " + page.filename().string());
    if (!anchor.empty() && !headings.anchors.count(anchor))
      broken.push_back(at + ": no heading #" + anchor + " on " + page.filename().string());
  };
  for (const TextFile& file : project_text_files()) {
    const bool markdown = file.relative.extension() == ".md";
    for (std::size_t i = 0; i < file.lines.size(); ++i) {
      const std::string& line = file.lines[i];
      // A citation may wrap: its heading read on with the next line, and counted on the
      // line where it starts.
      const std::string read_on = line + " " + continued_text(file, i + 1);
      const auto starts_on_line = [&](const std::smatch& m) {
        return static_cast<std::size_t>(m.position(0)) < line.size();
      };
      if (line.find("docs/") != std::string::npos) {
        for (std::sregex_iterator m(read_on.begin(), read_on.end(), kPageCitation), end; m != end;
             ++m) {
          if (!starts_on_line(*m)) continue;
          ++citations;
          const fs::path page = kTreeRoot / (*m)[1].str();
          if (!fs::exists(page))
            broken.push_back(line_at(file, i) + ": no page " + (*m)[1].str());
          else
            check_heading(page, (*m)[2], (*m)[3], line_at(file, i));
        }
      }
      if (line.find("README") != std::string::npos) {
        for (std::sregex_iterator m(read_on.begin(), read_on.end(), kReadmeCitation), end; m != end;
             ++m) {
          if (!starts_on_line(*m)) continue;
          ++citations;
          check_heading(kTreeRoot / "README.md", (*m)[1], "", line_at(file, i));
        }
      }
      if (!markdown || line.find("](") == std::string::npos) continue;
      for (std::sregex_iterator m(line.begin(), line.end(), kMarkdownLink), end; m != end; ++m) {
        const std::string target = (*m)[1];
        if (std::regex_search(target, std::regex("^[a-z]+:"))) continue;  // https:, mailto:
        ++citations;
        const std::size_t hash = target.find('#');
        const std::string path = target.substr(0, hash),
                          anchor = hash == std::string::npos ? "" : target.substr(hash + 1);
        const fs::path linked = path.empty() ? kTreeRoot / file.relative
                                             : (kTreeRoot / file.relative).parent_path() / path;
        if (!fs::exists(linked))
          broken.push_back(line_at(file, i) + ": link to a missing " + target);
        else if (!anchor.empty())
          check_heading(linked, "", anchor, line_at(file, i));
      }
    }
  }
  EXPECT_GT(citations, 100u) << "the walk found too few citations to be reading the tree";
  EXPECT_TRUE(broken.empty()) << ::testing::PrintToString(broken);
}

// A measured figure in the manual stands on a page of docs/results/ that a command makes:
// each page names its command near its top, ends with the stamp tests/results_stamp.sh
// writes (commit, date, machine), and is one that `make results` makes again.
TEST(Docs, EveryResultsPageNamesItsCommandIsStampedAndIsMadeAgainByMakeResults) {
  std::ifstream makefile_in(kTreeRoot / "Makefile");
  std::stringstream makefile;
  makefile << makefile_in.rdbuf();
  const std::string recipes = makefile.str();
  const std::size_t recipe_start = recipes.find("\nresults:");
  ASSERT_NE(recipe_start, std::string::npos) << "the Makefile has no results target";
  // The recipe ends at the first empty line.
  const std::string results_recipe =
      recipes.substr(recipe_start, recipes.find("\n\n", recipe_start) - recipe_start);
  std::size_t pages = 0;
  std::vector<std::string> faults;
  for (const TextFile& file : project_text_files()) {
    const std::string path = file.relative.generic_string();
    if (path.rfind("docs/results/", 0) != 0 || file.relative.extension() != ".md") continue;
    ++pages;
    const std::size_t top = std::min<std::size_t>(file.lines.size(), 5);
    if (std::none_of(file.lines.begin(), file.lines.begin() + static_cast<std::ptrdiff_t>(top),
                     [](const std::string& line) {
                       return line.find("writes this page") != std::string::npos;
                     }))
      faults.push_back(path + ": its first lines do not say which command writes this page");
    const auto last = std::find_if(file.lines.rbegin(), file.lines.rend(),
                                   [](const std::string& line) { return !line.empty(); });
    if (last == file.lines.rend() || last->rfind("_Measured at commit ", 0) != 0)
      faults.push_back(path + ": it does not end with tests/results_stamp.sh's stamp");
    if (results_recipe.find(path) == std::string::npos)
      faults.push_back(path + ": `make results` does not make it again");
  }
  EXPECT_GE(pages, 10u) << "the walk found too few results pages to be reading docs/results/";
  EXPECT_TRUE(faults.empty()) << ::testing::PrintToString(faults);
}

TEST(Docs, NoLineDatesItselfByTheProjectsDevelopment) {
  const std::string stage = "stage", change = "this change", engineer = "engineer";
  const std::regex dated("\\b(development |project )?" + stage +
                             "s? [0-9]+\\b|\\b(before|after|since|until) " + change + "\\b|\\b" +
                             engineer + "'?s build|\\b(another|other|a second) " + engineer +
                             "s?\\b",
                         std::regex::icase);
  std::size_t lines = 0;
  std::vector<std::string> dated_lines;
  for (const TextFile& file : project_text_files()) {
    if (file.relative == "CHANGELOG.md" || file.relative == "tests/test_docs.cpp") continue;
    for (std::size_t i = 0; i < file.lines.size(); ++i) {
      ++lines;
      std::string lower = file.lines[i];
      std::transform(lower.begin(), lower.end(), lower.begin(), [](char c) {
        return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      });
      const bool may_match = lower.find(stage) != std::string::npos ||
                             lower.find(change) != std::string::npos ||
                             lower.find(engineer) != std::string::npos;
      if (may_match && std::regex_search(file.lines[i], dated))
        dated_lines.push_back(line_at(file, i) + ": " + file.lines[i]);
    }
  }
  EXPECT_GT(lines, 50'000u) << "the walk found too few lines to be reading the tree";
  EXPECT_TRUE(dated_lines.empty()) << ::testing::PrintToString(dated_lines);
}

}  // namespace
}  // namespace cohaptic
