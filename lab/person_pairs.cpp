#include "lab/person_pairs.h"

#include <fmt/format.h>
#include <signal.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <istream>
#include <optional>
#include <ostream>
#include <regex>

#include "common/util/atomic_file.h"
#include "common/util/child_process.h"
#include "common/util/csv.h"
#include "common/util/error.h"
#include "lab/control_client.h"
#include "lab/rating_page.h"

namespace cohaptic {
namespace {

using namespace std::chrono_literals;

// One switch of the served condition (by the subject's command or the device's button), in
// the server's session time.
struct SwitchRow {
  int subject = 0;
  std::string pair;  // its position, or "practice-K"
  double time_s = 0;
  std::string serving;
};

// The switches in a pair's server report (its switch log), the pair labelled `pair`.
std::vector<SwitchRow> reported_switches(const std::filesystem::path& report, int subject,
                                         const std::string& pair) {
  std::ifstream in(report);
  const nlohmann::json parsed = nlohmann::json::parse(in, nullptr, false);
  if (parsed.is_discarded() || !parsed.contains("server") ||
      !parsed["server"].contains("switch_log"))
    throw Error(
        fmt::format("{}: the pair's server left no report with its switches (its log is beside it)",
                    report.string()));
  std::vector<SwitchRow> rows;
  for (const nlohmann::json& made : parsed["server"]["switch_log"])
    rows.push_back(
        {subject, pair, made.at("time_s").get<double>(), made.at("served").get<std::string>()});
  return rows;
}

void append_switches(const std::filesystem::path& file, const std::vector<SwitchRow>& rows) {
  std::string text;
  if (std::filesystem::exists(file)) {
    std::ifstream in(file);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  } else {
    text = "subject,pair,time_s,serving\n";
  }
  for (const SwitchRow& row : rows)
    text +=
        fmt::format("{},{},{:.6f},{}\n", row.subject, csv_field(row.pair), row.time_s, row.serving);
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

// A grade as the scale shows it: "+2", "0", "-1".
std::string grade_text(int grade) { return grade == 0 ? "0" : fmt::format("{:+d}", grade); }

std::string trimmed(const std::string& line) {
  const auto begin = line.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  return line.substr(begin, line.find_last_not_of(" \t\r") - begin + 1);
}

// A subject may deliberate after the pair's time is up: the server (the control socket, the
// switch log) stays this long beyond it, unless the pair ends first (it usually does: the
// session stops the server then). Only a lab process killed outright leaves it to end itself.
constexpr double kServerBeyondPair_s = 3600;

// The pair's two conditions served to one client, until destroyed.
class PairServing {
 public:
  PairServing(const PersonSessionSetup& setup, int first, int second, bool show_object,
              const std::filesystem::path& dir) {
    std::filesystem::create_directories(dir);
    const double duration = setup.design.pair_duration_s;
    std::vector<std::string> server_arguments = {
        "--scene",        setup.scene.string(),
        "--listen",       "127.0.0.1:0",
        "--condensation", setup.condensation,
        "--condition",    "first:" + setup.condition_settings[static_cast<std::size_t>(first)],
        "--condition",    "second:" + setup.condition_settings[static_cast<std::size_t>(second)],
        "--control",      (dir / "control").string(),
        "--duration",     fmt::format("{:g}", duration + kServerBeyondPair_s),
        "--record",       (dir / "server.mcap").string(),
        "--report",       (dir / "server.json").string()};
    if (setup.design.switch_button >= 0)
      server_arguments.insert(server_arguments.end(),
                              {"--switch-button", std::to_string(setup.design.switch_button)});
    if (show_object) server_arguments.insert(server_arguments.end(), {"--view", "127.0.0.1:0"});
    server_.emplace(setup.server_program, server_arguments, dir / "server.log");
    if (!server_->wait_for_log("listening on", 120s))
      throw Error(fmt::format("the server did not start (see {})", (dir / "server.log").string()));
    const int port = listening_port(server_->log_text());
    client_.emplace(setup.client_program,
                    std::vector<std::string>{"--server", fmt::format("127.0.0.1:{}", port),
                                             "--user", fmt::format("subject-{}", setup.subject),
                                             "--slot", "0", "--device", setup.device, "--duration",
                                             fmt::format("{:g}", duration), "--record",
                                             (dir / "subject.mcap").string(), "--report",
                                             (dir / "subject.json").string()},
                    dir / "subject.log");
    if (!client_->wait_for_log("haptic thread", 60s))
      throw Error(fmt::format("the client did not start (see {})", (dir / "subject.log").string()));
    ends_ = std::chrono::steady_clock::now() +
            std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                std::chrono::duration<double>(duration));
    control_.emplace(dir / "control");
    if (show_object) {
      static const std::regex kView(R"(live view at (\S+))");
      std::smatch match;
      const std::string log = server_->log_text();
      if (std::regex_search(log, match, kView)) view_url_ = match[1];
    }
  }

  /// Stops the client and the server, which writes its report (server.json: its switch log).
  ~PairServing() {
    control_.reset();
    for (ChildProcess* process : {client_ ? &*client_ : nullptr, server_ ? &*server_ : nullptr})
      if (process && process->running()) {
        process->signal(SIGINT);
        process->wait(30s);
      }
  }

  /// Serves the other condition ("first" or "second", whichever the server does not serve
  /// now, whoever switched last); returns it.
  std::string switch_over() { return control_->serve_next().value("served", ""); }
  /// The condition served now.
  std::string served() { return control_->ask({{"status", true}}).value("served", ""); }
  /// Whether the pair's time (pair_duration) is over: the client has stopped.
  bool time_up() const { return std::chrono::steady_clock::now() >= ends_; }
  const std::string& view_url() const { return view_url_; }

 private:
  std::chrono::steady_clock::time_point ends_;
  std::optional<ChildProcess> server_, client_;
  std::optional<ControlClient> control_;
  std::string view_url_;
};

enum class PairEnd { rated, next, stopped };

// Where the subject's commands come from: the rating page when there is one (the terminal
// then only reports), else the terminal. What the page shows follows every change.
class SubjectInput {
 public:
  SubjectInput(std::istream& terminal, RatingPage* page) : terminal_(terminal), page_(page) {}

  /// The next command, trimmed; nothing when the terminal's input has ended. A command from
  /// the page is echoed on `out`, so the terminal reads as a log of the session; while the
  /// page has none, `waiting` is called every quarter second.
  std::optional<std::string> next(std::ostream& out, const std::function<void()>& waiting) {
    if (page_) {
      for (;;) {
        if (std::optional<std::string> line = page_->next_command(250ms)) {
          out << *line << "  (rating page)\n" << std::flush;
          return line;
        }
        waiting();
      }
    }
    std::string line;
    if (!std::getline(terminal_, line)) return std::nullopt;
    return trimmed(line);
  }

  void show(const view::RatingScreen& screen) {
    if (page_) page_->show(screen);
  }

 private:
  std::istream& terminal_;
  RatingPage* page_;
};

// The rating page's screen between pairs: no condition served.
view::RatingScreen idle_screen(const PersonSessionSetup& setup, const std::string& note, int rated,
                               int pairs) {
  view::RatingScreen screen;
  screen.set_study(setup.study_name);
  screen.set_question(setup.design.question);
  screen.set_note(note);
  screen.set_rated(static_cast<std::uint32_t>(rated));
  screen.set_pairs(static_cast<std::uint32_t>(pairs));
  return screen;
}

// One pair: the subject switches, and (unless practice) rates; `rating` is set when rated.
// `screen` comes with the session's fields set.
PairEnd present_pair(const PersonSessionSetup& setup, PairServing& serving,
                     view::RatingScreen screen, SubjectInput& input, std::ostream& out,
                     int& rating) {
  const PairedComparisonDesign& design = setup.design;
  const bool practice = screen.practice();
  out << fmt::format("\n{}: {}\n", screen.title(), design.question);
  if (!serving.view_url().empty())
    out << fmt::format("  the object: open {} in a browser\n", serving.view_url());
  out << fmt::format(
      "  s: switch between FIRST and SECOND, as often as you like; {}; q: stop (continue later)\n",
      practice ? "n: on to the next pair" : "a grade to rate");
  for (int grade = design.grades, i = 0; grade >= -design.grades; --grade, ++i) {
    const std::string& label = design.labels[static_cast<std::size_t>(i)];
    if (!practice) out << fmt::format("    {:>2}  {}\n", grade_text(grade), label);
    view::RatingScreen::Grade& shown = *screen.add_grades();
    shown.set_value(grade);
    shown.set_label(label);
  }
  screen.set_serving(true);
  screen.set_object_url(serving.view_url());
  screen.set_feeling("first");
  screen.set_note(
      practice ? "Feel both, switching as often as you like, then go on to the next pair"
               : "Feel both, switching as often as you like, then choose a grade and confirm it");
  out << "  You are feeling: FIRST\n> " << std::flush;
  input.show(screen);
  const auto feeling = [&](const std::string& served, const char* how) {
    screen.set_feeling(served);
    out << fmt::format("  {}You are feeling: {}\n> ", how, served == "first" ? "FIRST" : "SECOND")
        << std::flush;
  };
  // The device's button switches without us: follow it before each command, and while the
  // page waits for one.
  const auto follow_button = [&] {
    if (design.switch_button < 0) return;
    if (const std::string served = serving.served(); served != screen.feeling()) {
      feeling(served, "(button) ");
      input.show(screen);
    }
  };
  std::optional<int> chosen;
  while (const std::optional<std::string> line = input.next(out, follow_button)) {
    follow_button();
    if (*line == "s" && serving.time_up()) {
      screen.set_note(practice ? "The pair's time is up: go on to the next pair"
                               : "The pair's time is up: rate it");
      out << fmt::format("  {}\n> ", screen.note()) << std::flush;
    } else if (*line == "s") {
      feeling(serving.switch_over(), "");
    } else if (*line == "q") {
      return PairEnd::stopped;
    } else if (practice && *line == "n") {
      return PairEnd::next;
    } else if (const std::optional<int> grade =
                   practice ? std::nullopt : grade_of(*line, design.grades)) {
      chosen = grade;
      screen.set_chosen(true);
      screen.set_chosen_grade(*grade);
      const std::string& label = design.labels[static_cast<std::size_t>(design.grades - *grade)];
      screen.set_note(
          fmt::format("{}: {}. Confirm, or choose another grade", grade_text(*grade), label));
      out << fmt::format("  {}: {}. Enter (or y) to confirm, another grade to change\n> ",
                         grade_text(*grade), label)
          << std::flush;
    } else if (chosen && (line->empty() || *line == "y")) {
      rating = *chosen;
      return PairEnd::rated;
    } else {
      out << (practice ? "  s, n or q\n> "
                       : fmt::format("  s, a grade from {:+d} to {:+d}, or q\n> ", design.grades,
                                     -design.grades))
          << std::flush;
      continue;
    }
    input.show(screen);
  }
  return PairEnd::stopped;  // the input ended
}

}  // namespace

bool run_person_pairs(const PersonSessionSetup& setup, std::istream& in, std::ostream& out,
                      RatingPage* page) {
  const PairedComparisonDesign& design = setup.design;
  if (setup.subject < 1 || setup.subject > design.subjects)
    throw Error(fmt::format("--subject {}: the study has subjects 1 to {}", setup.subject,
                            design.subjects));
  const int conditions = static_cast<int>(setup.condition_names.size());
  std::vector<PresentedPair> plan;
  for (const PresentedPair& pair : presentation_plan(conditions, design.subjects))
    if (pair.subject == setup.subject - 1) plan.push_back(pair);
  const std::filesystem::path ratings_file = setup.out / "ratings.csv",
                              switches_file = setup.out / "switches.csv";
  std::vector<PairRatingRow> ratings = read_ratings(ratings_file);
  const auto rated = [&](int position) {
    return std::any_of(ratings.begin(), ratings.end(), [&](const PairRatingRow& r) {
      return r.subject == setup.subject && r.position == position;
    });
  };
  const std::size_t done = static_cast<std::size_t>(
      std::count_if(plan.begin(), plan.end(),
                    [&](const PresentedPair& pair) { return rated(pair.position + 1); }));
  out << fmt::format("study '{}', subject {} of {}: {} pairs, {} rated{}\n", setup.study_name,
                     setup.subject, design.subjects, plan.size(), done,
                     done == 0 && design.practice_pairs > 0
                         ? fmt::format("; {} practice pair(s) first", design.practice_pairs)
                         : "");
  const auto pair_dir = [&](const std::string& label) {
    return setup.out / "pairs" / fmt::format("s{:02d}-{}", setup.subject, label);
  };
  SubjectInput input(in, page);
  int rated_now = static_cast<int>(done);
  const int pairs = static_cast<int>(plan.size());
  const auto screen_of = [&](const std::string& title, bool practice) {
    view::RatingScreen screen = idle_screen(setup, "", rated_now, pairs);
    screen.set_title(title);
    screen.set_practice(practice);
    return screen;
  };
  const auto setting_up = [&](const std::string& title) {
    input.show(idle_screen(setup, title + ": starting…", rated_now, pairs));
  };
  const auto stop = [&] {
    input.show(idle_screen(setup,
                           "Stopped: the experimenter runs the same command again to continue",
                           rated_now, pairs));
    return false;
  };
  // Practice: felt, not rated, before the first rated pair only; the last pairs of the plan.
  for (int k = 0; done == 0 && k < design.practice_pairs && k < static_cast<int>(plan.size());
       ++k) {
    const PresentedPair& pair = plan[plan.size() - 1 - static_cast<std::size_t>(k)];
    const std::string label = fmt::format("practice-{}", k + 1);
    const std::string title =
        fmt::format("Practice pair {} of {} (not rated)", k + 1, design.practice_pairs);
    setting_up(title);
    std::optional<PairServing> serving;
    serving.emplace(setup, pair.first, pair.second, design.show_object != "never", pair_dir(label));
    int unused = 0;
    const PairEnd end = present_pair(setup, *serving, screen_of(title, true), input, out, unused);
    serving.reset();
    append_switches(switches_file,
                    reported_switches(pair_dir(label) / "server.json", setup.subject, label));
    if (end == PairEnd::stopped) return stop();
  }
  for (const PresentedPair& pair : plan) {
    const int position = pair.position + 1;
    if (rated(position)) continue;
    const std::string label = fmt::format("p{:02d}", position);
    const std::string title = fmt::format("Pair {} of {}", position, plan.size());
    setting_up(title);
    std::optional<PairServing> serving;
    serving.emplace(setup, pair.first, pair.second, design.show_object == "always",
                    pair_dir(label));
    int rating = 0;
    const PairEnd end = present_pair(setup, *serving, screen_of(title, false), input, out, rating);
    if (end == PairEnd::rated) {
      ratings.push_back(
          {setup.subject, position, setup.condition_names[static_cast<std::size_t>(pair.first)],
           setup.condition_names[static_cast<std::size_t>(pair.second)], rating, "person"});
      write_ratings(ratings_file, ratings);  // at once: an interruption loses no rating
      ++rated_now;
    }
    serving.reset();
    append_switches(switches_file, reported_switches(pair_dir(label) / "server.json", setup.subject,
                                                     std::to_string(position)));
    if (end != PairEnd::rated) return stop();
  }
  out << fmt::format("subject {} has rated every pair\n", setup.subject);
  input.show(idle_screen(setup, "Every pair is rated: thank you", rated_now, pairs));
  return true;
}

}  // namespace cohaptic
