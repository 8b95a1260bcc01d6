#include "lab/person_pairs.h"

#include <fmt/format.h>
#include <signal.h>

#include <algorithm>
#include <fstream>
#include <istream>
#include <optional>
#include <ostream>
#include <regex>

#include "common/util/atomic_file.h"
#include "common/util/child_process.h"
#include "common/util/csv.h"
#include "common/util/error.h"
#include "lab/control_client.h"

namespace cohaptic {
namespace {

using namespace std::chrono_literals;

// One switch a subject made, in the server's session time.
struct SwitchRow {
  int subject = 0;
  std::string pair;  // its position, or "practice-K"
  double time_s = 0;
  std::string serving;
};

void append_switches(const std::filesystem::path& file, const std::vector<SwitchRow>& rows) {
  std::string text;
  if (std::filesystem::exists(file)) {
    std::ifstream in(file);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  } else {
    text = "subject,pair,time_s,serving\n";
  }
  for (const SwitchRow& row : rows) text += fmt::format("{},{},{:.6f},{}\n", row.subject, csv_field(row.pair), row.time_s, row.serving);
  AtomicFile out(file);
  out.write(text);
  out.commit();
}

// The grade a line chooses, if it is one: "+2", "2", "-1", "0".
std::optional<int> grade_of(const std::string& line, int grades) {
  static const std::regex kGrade(R"(^\s*([+-]?)([0-9])\s*$)");
  std::smatch match;
  if (!std::regex_match(line, match, kGrade)) return std::nullopt;
  const int grade = (match[1] == "-" ? -1 : 1) * std::stoi(match[2]);
  if (std::abs(grade) > grades) return std::nullopt;
  return grade;
}

std::string trimmed(const std::string& line) {
  const auto begin = line.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  return line.substr(begin, line.find_last_not_of(" \t\r") - begin + 1);
}

// The pair's two conditions served to one client, until destroyed.
class PairServing {
 public:
  PairServing(const PersonSessionSetup& setup, int first, int second, bool show_object,
              const std::filesystem::path& dir) {
    std::filesystem::create_directories(dir);
    const double duration = setup.design.pair_duration_s;
    std::vector<std::string> server_arguments = {
        "--scene", setup.scene.string(), "--listen", "127.0.0.1:0", "--condensation", setup.condensation,
        "--condition", "first:" + setup.condition_settings[static_cast<std::size_t>(first)],
        "--condition", "second:" + setup.condition_settings[static_cast<std::size_t>(second)],
        "--control", (dir / "control").string(), "--duration", fmt::format("{:g}", duration + 30),
        "--record", (dir / "server.mcap").string(), "--report", (dir / "server.json").string()};
    if (show_object) server_arguments.insert(server_arguments.end(), {"--view", "127.0.0.1:0"});
    server_.emplace(setup.server_program, server_arguments, dir / "server.log");
    if (!server_->wait_for_log("listening on", 120s))
      throw Error(fmt::format("the server did not start (see {})", (dir / "server.log").string()));
    const int port = listening_port(server_->log_text());
    client_.emplace(setup.client_program,
                    std::vector<std::string>{"--server", fmt::format("127.0.0.1:{}", port), "--user",
                                             fmt::format("subject-{}", setup.subject), "--slot", "0", "--device",
                                             setup.device, "--duration", fmt::format("{:g}", duration), "--record",
                                             (dir / "subject.mcap").string(), "--report", (dir / "subject.json").string()},
                    dir / "subject.log");
    if (!client_->wait_for_log("haptic thread", 60s))
      throw Error(fmt::format("the client did not start (see {})", (dir / "subject.log").string()));
    control_.emplace(dir / "control");
    if (show_object) {
      static const std::regex kView(R"(live view at (\S+))");
      std::smatch match;
      const std::string log = server_->log_text();
      if (std::regex_search(log, match, kView)) view_url_ = match[1];
    }
  }

  ~PairServing() {
    control_.reset();
    for (ChildProcess* process : {client_ ? &*client_ : nullptr, server_ ? &*server_ : nullptr})
      if (process && process->running()) {
        process->signal(SIGINT);
        process->wait(30s);
      }
  }

  /// Serves "first" or "second"; returns the server's session time of the switch [s].
  double serve(const std::string& which) { return control_->serve(which).value("time_s", 0.0); }
  const std::string& view_url() const { return view_url_; }

 private:
  std::optional<ChildProcess> server_, client_;
  std::optional<ControlClient> control_;
  std::string view_url_;
};

enum class PairEnd { rated, next, stopped };

// One pair on the terminal: the subject switches, and (unless practice) rates. `rating` is
// set when rated; the switches made are appended to `switches`.
PairEnd present_pair(const PersonSessionSetup& setup, PairServing& serving, const std::string& title, bool practice,
                     std::istream& in, std::ostream& out, int& rating, std::vector<SwitchRow>& switches,
                     const std::string& pair_label) {
  const PairedComparisonDesign& design = setup.design;
  out << fmt::format("\n{}: {}\n", title, design.question);
  if (!serving.view_url().empty()) out << fmt::format("  the object: open {} in a browser\n", serving.view_url());
  out << fmt::format("  s: switch between FIRST and SECOND, as often as you like; {}; q: stop (continue later)\n",
                     practice ? "n: on to the next pair" : "a grade to rate");
  if (!practice)
    for (int grade = design.grades, i = 0; grade >= -design.grades; --grade, ++i)
      out << fmt::format("    {:>2}  {}\n", grade == 0 ? "0" : fmt::format("{:+d}", grade), design.labels[static_cast<std::size_t>(i)]);
  std::string felt = "first";
  out << "  You are feeling: FIRST\n> " << std::flush;
  std::optional<int> chosen;
  std::string line;
  while (std::getline(in, line)) {
    line = trimmed(line);
    if (line == "s") {
      felt = felt == "first" ? "second" : "first";
      switches.push_back({setup.subject, pair_label, serving.serve(felt), felt});
      out << fmt::format("  You are feeling: {}\n> ", felt == "first" ? "FIRST" : "SECOND") << std::flush;
    } else if (line == "q") {
      return PairEnd::stopped;
    } else if (practice && line == "n") {
      return PairEnd::next;
    } else if (const std::optional<int> grade = practice ? std::nullopt : grade_of(line, design.grades)) {
      chosen = grade;
      out << fmt::format("  {:+d}: {}. Enter (or y) to confirm, another grade to change\n> ", *grade,
                         design.labels[static_cast<std::size_t>(design.grades - *grade)])
          << std::flush;
    } else if (chosen && (line.empty() || line == "y")) {
      rating = *chosen;
      return PairEnd::rated;
    } else {
      out << (practice ? "  s, n or q\n> " : fmt::format("  s, a grade from {:+d} to {:+d}, or q\n> ", design.grades, -design.grades))
          << std::flush;
    }
  }
  return PairEnd::stopped;  // the input ended
}

}  // namespace

bool run_person_pairs(const PersonSessionSetup& setup, std::istream& in, std::ostream& out) {
  const PairedComparisonDesign& design = setup.design;
  if (setup.subject < 1 || setup.subject > design.subjects)
    throw Error(fmt::format("--subject {}: the study has subjects 1 to {}", setup.subject, design.subjects));
  const int conditions = static_cast<int>(setup.condition_names.size());
  std::vector<PresentedPair> plan;
  for (const PresentedPair& pair : presentation_plan(conditions, design.subjects))
    if (pair.subject == setup.subject - 1) plan.push_back(pair);
  const std::filesystem::path ratings_file = setup.out / "ratings.csv", switches_file = setup.out / "switches.csv";
  std::vector<PairRatingRow> ratings = read_ratings(ratings_file);
  const auto rated = [&](int position) {
    return std::any_of(ratings.begin(), ratings.end(),
                       [&](const PairRatingRow& r) { return r.subject == setup.subject && r.position == position; });
  };
  const std::size_t done = static_cast<std::size_t>(std::count_if(
      plan.begin(), plan.end(), [&](const PresentedPair& pair) { return rated(pair.position + 1); }));
  out << fmt::format("study '{}', subject {} of {}: {} pairs, {} rated{}\n", setup.study_name, setup.subject,
                     design.subjects, plan.size(), done, done == 0 && design.practice_pairs > 0
                                                              ? fmt::format("; {} practice pair(s) first", design.practice_pairs)
                                                              : "");
  const auto pair_dir = [&](const std::string& label) {
    return setup.out / "pairs" / fmt::format("s{:02d}-{}", setup.subject, label);
  };
  // Practice: felt, not rated, before the first rated pair only; the last pairs of the plan.
  for (int k = 0; done == 0 && k < design.practice_pairs && k < static_cast<int>(plan.size()); ++k) {
    const PresentedPair& pair = plan[plan.size() - 1 - static_cast<std::size_t>(k)];
    const std::string label = fmt::format("practice-{}", k + 1);
    PairServing serving(setup, pair.first, pair.second, design.show_object != "never", pair_dir(label));
    std::vector<SwitchRow> switches;
    int unused = 0;
    const PairEnd end = present_pair(setup, serving, fmt::format("Practice pair {} of {} (not rated)", k + 1, design.practice_pairs),
                                     true, in, out, unused, switches, label);
    append_switches(switches_file, switches);
    if (end == PairEnd::stopped) return false;
  }
  for (const PresentedPair& pair : plan) {
    const int position = pair.position + 1;
    if (rated(position)) continue;
    const std::string label = fmt::format("p{:02d}", position);
    PairServing serving(setup, pair.first, pair.second, design.show_object == "always", pair_dir(label));
    std::vector<SwitchRow> switches;
    int rating = 0;
    const PairEnd end = present_pair(setup, serving, fmt::format("Pair {} of {}", position, plan.size()), false, in, out,
                                     rating, switches, std::to_string(position));
    append_switches(switches_file, switches);
    if (end != PairEnd::rated) return false;
    ratings.push_back({setup.subject, position, setup.condition_names[static_cast<std::size_t>(pair.first)],
                       setup.condition_names[static_cast<std::size_t>(pair.second)], rating, "person"});
    write_ratings(ratings_file, ratings);  // at once: an interruption loses no rating
  }
  out << fmt::format("subject {} has rated every pair\n", setup.subject);
  return true;
}

}  // namespace cohaptic
