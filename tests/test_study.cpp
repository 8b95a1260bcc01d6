// The study runner: study files are parsed and checked (errors name the key), the trial
// order is what the file asks for (a seeded shuffle, or a balanced Latin square), and a
// two-condition study runs with the real programs: P0 renders at the rate of the slowed
// simulation, P1 at its haptic rate; an interrupted study continues where it stopped; on a
// machine slowed by busy processes a press is still one stroke, and a fade is reported.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <sched.h>

#include <nlohmann/json.hpp>
#include <regex>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <streambuf>
#include <thread>
#include <vector>

#include "common/util/csv.h"
#include "common/util/error.h"
#include "lab/study.h"
#include "proto/record/recording.h"
#include "support/browser.h"
#include "support/csv_table.h"
#include "support/cube_scene.h"
#include "support/process.h"

namespace cohaptic {
namespace {

namespace fs = std::filesystem;

// A small cube pressed open loop (a scripted device), so every trial presses the same.
void write_study_files(const fs::path& dir, const std::string& study_body) {
  std::ofstream(dir / "cube.yaml") << testing::cube_scene_yaml(testing::pressed_cube_options());
  std::ofstream(dir / "press.yaml") << R"(
units: mm
start: [4, 3, 4]
segments:
  - {move_to: [4, 3, 0.5], speed: 20}
  - {press: 0.75, speed: 0.75, direction: [0, 0, -1]}
  - {release: 0.75, speed: 0.75}
)";
  std::ofstream(dir / "study.yaml") << study_body;
}

std::string study_text(const std::string& factors, const std::string& order = "{kind: sequential}",
                       int repetitions = 1) {
  return fmt::format(R"(name: test-study
scene: cube.yaml
trial_duration: 2.8
condensation: naive
participants:
  - {{name: s1, device: script, trajectory: press.yaml}}
factors:
{}
repetitions: {}
order: {}
session: {{site: ci}}
)",
                     factors, repetitions, order);
}

// The error loading a study file with `body` gives ("no error" if none).
std::string study_file_error(const fs::path& dir, const std::string& body) {
  write_study_files(dir, body);
  try {
    load_study(dir / "study.yaml");
  } catch (const Error& e) {
    return std::string(e.what());
  }
  return std::string("no error");
}

TEST(StudyFile, CrossesTheFactorsAndOrdersTheTrialsAsAsked) {
  const fs::path dir = testing::scratch_directory("study-file");
  write_study_files(dir,
                    study_text("  shift_ms: [0, 30]\n  step_nodes: [0, 150]\n  protocol: [P0, P1]",
                               "{kind: random, seed: 7}", 2));
  const Study study = load_study(dir / "study.yaml");
  ASSERT_EQ(study.conditions.size(), 8u);
  ASSERT_EQ(study.trials.size(), 16u);
  std::set<std::string> names;
  for (const StudyCondition& c : study.conditions) names.insert(c.name());
  EXPECT_EQ(names.size(), 8u);
  EXPECT_TRUE(names.count("S30-T150-P1"));
  // Each repetition runs every condition once; the seed makes the order reproducible and
  // the two repetitions differ.
  std::vector<std::string> first, second;
  for (const StudyTrial& t : study.trials)
    (t.repetition == 1 ? first : second).push_back(t.condition.name());
  EXPECT_EQ(std::set<std::string>(first.begin(), first.end()), names);
  EXPECT_EQ(std::set<std::string>(second.begin(), second.end()), names);
  EXPECT_NE(first, second);
  const Study again = load_study(dir / "study.yaml");
  for (std::size_t i = 0; i < study.trials.size(); ++i)
    EXPECT_EQ(again.trials[i].condition.name(), study.trials[i].condition.name());
}

TEST(StudyFile, ALatinSquareBalancesPositionsAndSuccessions) {
  const fs::path dir = testing::scratch_directory("study-latin");
  write_study_files(
      dir, study_text("  step_nodes: [0, 150]\n  protocol: [P0, P1]", "{kind: latin_square}", 4));
  const Study study = load_study(dir / "study.yaml");
  ASSERT_EQ(study.trials.size(), 16u);
  // Every condition once in every position, and every ordered pair of conditions once as
  // neighbours (Williams design, n = 4): order and carry-over effects are balanced.
  std::map<std::pair<std::size_t, std::string>, int> position_count;
  std::map<std::pair<std::string, std::string>, int> succession_count;
  for (std::size_t k = 0; k < study.trials.size(); ++k) {
    position_count[{k % 4, study.trials[k].condition.name()}]++;
    if (k % 4 != 3)
      succession_count[{study.trials[k].condition.name(), study.trials[k + 1].condition.name()}]++;
  }
  EXPECT_EQ(position_count.size(), 16u);
  for (const auto& [key, count] : position_count)
    EXPECT_EQ(count, 1) << key.second << " at " << key.first;
  EXPECT_EQ(succession_count.size(), 12u);
  for (const auto& [pair, count] : succession_count)
    EXPECT_EQ(count, 1) << pair.first << " -> " << pair.second;
}

TEST(StudyFile, MistakesAreNamedWithTheirKey) {
  const fs::path dir = testing::scratch_directory("study-errors");
  const auto error_of = [&](const std::string& body) { return study_file_error(dir, body); };
  std::string e = error_of(study_text("  shift_ms: [0, -5]"));
  EXPECT_NE(e.find("study.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("factors.shift_ms"), std::string::npos) << e;
  e = error_of(study_text("  shift_ms: [0]\n  stepnodes: [150]"));
  EXPECT_NE(e.find("stepnodes"), std::string::npos) << e;
  e = error_of(study_text("  protocol: [P2]"));
  EXPECT_NE(e.find("P2"), std::string::npos) << e;
  e = error_of(study_text("  shift_ms: [0]", "{kind: shuffled}"));
  EXPECT_NE(e.find("order.kind"), std::string::npos) << e;
  std::string body = study_text("  shift_ms: [0]");
  e = error_of(body.replace(body.find("{site: ci}"), 10, "{protocol: x}"));
  EXPECT_NE(e.find("column of trials.csv"), std::string::npos) << e;
  body = study_text("  shift_ms: [0]");
  const std::string one = "  - {name: s1, device: script, trajectory: press.yaml}\n";
  e = error_of(body.insert(body.find(one) + one.size(),
                           "  - {name: s2, device: script, trajectory: press.yaml}\n"));
  EXPECT_NE(e.find("2 participants, but the scene"), std::string::npos) << e;
  e = error_of("scene: nowhere.yaml\nparticipants: []\nfactors: {}\n");
  EXPECT_NE(e.find("nowhere.yaml"), std::string::npos) << e;
}

TEST(Study, TwoConditionsRunWithTheRealProgramsAndAnInterruptedStudyContinues) {
  const fs::path dir = testing::scratch_directory("study-run");
  write_study_files(dir, study_text("  step_nodes: [150]\n  protocol: [P0, P1]"));
  StudyRunOptions options;
  options.out = dir / "out";
  options.server_program = testing::server_program();
  options.client_program = testing::client_program();
  ASSERT_EQ(run_study(dir / "study.yaml", options), 0);

  auto rows = testing::read_csv_table(options.out / "trials.csv");
  ASSERT_EQ(rows.size(), 2u);
  std::map<std::string, std::map<std::string, std::string>> by_protocol;
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "ok");
    EXPECT_EQ(row.at("site"), "ci");
    EXPECT_EQ(row.at("step_nodes"), "150");
    by_protocol[row.at("protocol")] = row;
  }
  const auto value = [&](const char* protocol, const char* column) {
    return std::stod(by_protocol[protocol].at(column));
  };
  // P0: the hand meets each simulation step once, so the force changes at the simulation's
  // rate in contact: within 25 %, or 3 steps over the contact time when the simulation is
  // slow (a loaded machine), since the client's stroke and the server's pressing steps
  // differ at their edges (the slow first step of a contact, when the held nodes join);
  // P1: the client re-evaluates the IR every tick.
  const double p0_rate = value("P0", "force_update_rate_hz");
  const double p0_sim = value("P0", "contact_sim_rate_hz");
  const double edge_margin = std::max(0.25 * p0_sim, 3 / value("P0", "contact_time_s"));
  const double p1_rate = value("P1", "force_update_rate_hz");
  std::printf(
      "  P0: force updates %.0f/s, simulation %.0f/s in contact; P1: force updates %.0f/s "
      "(simulation %.0f/s)\n",
      p0_rate, p0_sim, p1_rate, value("P1", "contact_sim_rate_hz"));
  EXPECT_GT(p0_rate, 0);
  EXPECT_LE(p0_rate, p0_sim + edge_margin);
  EXPECT_GE(p0_rate, p0_sim - edge_margin);
  EXPECT_GT(p1_rate, 2 * p0_rate);
  EXPECT_GT(p1_rate, 300);
  for (const char* protocol : {"P0", "P1"}) {
    EXPECT_GT(value(protocol, "peak_force_n"), 0.1) << protocol;
    EXPECT_LT(value(protocol, "peak_force_n"), 3.3)
        << protocol << ": below the force limit, not clamped";
    EXPECT_EQ(value(protocol, "n_strokes"), 1) << protocol;
  }

  // summary.csv: mean of one trial = its value, n = 1, for every measure.
  const auto summary = testing::read_csv_table(options.out / "summary.csv");
  bool found = false;
  for (const auto& row : summary)
    if (row.at("condition") == "S0-T150-P1" && row.at("measure") == "force_update_rate_hz") {
      EXPECT_NEAR(std::stod(row.at("mean")), p1_rate, 1e-6 * p1_rate);
      EXPECT_EQ(row.at("n"), "1");
      found = true;
    }
  EXPECT_TRUE(found);
  for (const char* figure : {"fig4.svg", "force_update_rate_hz.svg", "terminal_force_ratio.svg"})
    EXPECT_GT(fs::file_size(options.out / "figures" / figure), 1000u) << figure;
  for (const char* recording : {"server.mcap", "s1.mcap"})
    EXPECT_GT(fs::file_size(options.out / "trials" / "001" / recording), 1000u) << recording;

  // Interrupted after the first trial: drop the second row; a re-run runs only that trial
  // and leaves the first one's recording alone.
  {
    std::ifstream in(options.out / "trials.csv");
    std::string header, first;
    std::getline(in, header);
    std::getline(in, first);
    std::ofstream(options.out / "trials.csv") << header << "\n" << first << "\n";
  }
  const auto first_recording_time = fs::last_write_time(options.out / "trials" / "001" / "s1.mcap");
  ASSERT_EQ(run_study(dir / "study.yaml", options), 0);
  rows = testing::read_csv_table(options.out / "trials.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("trial"), "1");
  EXPECT_EQ(rows[1].at("trial"), "2");
  EXPECT_EQ(fs::last_write_time(options.out / "trials" / "001" / "s1.mcap"), first_recording_time);

  // The same output directory with a different plan is refused.
  write_study_files(dir, study_text("  step_nodes: [150]\n  protocol: [P1, P0]"));
  EXPECT_THROW(run_study(dir / "study.yaml", options), Error);
}

// Three processes spin on the one CPU this thread, and the programs it starts, may use: the
// server builds the step-delayed IR late, so the client's force may fade in mid-press (its
// IR unconfirmed past the fade age) and come back. Each trial counts its one press as one
// stroke all the same, and reports its fades.
TEST(Study, OnAMachineSlowedByBusyProcessesAPressIsStillOneStroke) {
  cpu_set_t allowed;
  ASSERT_EQ(sched_getaffinity(0, sizeof allowed, &allowed), 0);
  int cpu = 0;
  while (!CPU_ISSET(cpu, &allowed)) ++cpu;
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(cpu, &one);
  ASSERT_EQ(sched_setaffinity(0, sizeof one, &one), 0);
  struct RestoreAffinity {
    cpu_set_t& allowed;
    ~RestoreAffinity() { sched_setaffinity(0, sizeof allowed, &allowed); }
  } restore{allowed};

  const fs::path dir = testing::scratch_directory("study-slowed");
  std::vector<std::unique_ptr<ChildProcess>> busy;
  for (int i = 0; i < 3; ++i)
    busy.push_back(std::make_unique<ChildProcess>(
        "/bin/sh", std::vector<std::string>{"-c", "while :; do :; done"},
        dir / fmt::format("busy{}.log", i)));
  write_study_files(
      dir, study_text("  step_nodes: [150]\n  protocol: [P1, P0]", "{kind: sequential}", 2));
  StudyRunOptions options;
  options.out = dir / "out";
  options.server_program = testing::server_program();
  options.client_program = testing::client_program();
  ASSERT_EQ(run_study(dir / "study.yaml", options), 0);
  busy.clear();  // killed

  const auto rows = testing::read_csv_table(options.out / "trials.csv");
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& row : rows) {
    const std::string trial = row.at("condition") + " #" + row.at("repetition");
    std::printf("  %s: %s stroke(s), %s fade(s) (%s s), peak %s N\n", trial.c_str(),
                row.at("n_strokes").c_str(), row.at("fades").c_str(), row.at("fade_s").c_str(),
                row.at("peak_force_n").c_str());
    EXPECT_EQ(row.at("status"), "ok") << trial;
    EXPECT_EQ(std::stod(row.at("n_strokes")), 1) << trial;
    EXPECT_GE(std::stod(row.at("fades")), 0) << trial << ": the client's report counts its fades";
    EXPECT_GE(std::stod(row.at("fade_s")), 0) << trial;
  }
}

// A paired-comparison block: the conditions' trials, then simulated subjects' ratings.
std::string paired_study_text(const std::string& factors, int subjects) {
  return study_text(factors) + fmt::format(R"(paired_comparison:
  quality: finer
  subjects: {}
  rater: {{kind: simulated, seed: 7}}
)",
                                           subjects);
}

TEST(PairedComparisonStudyFile, MistakesAreNamedWithTheirKey) {
  const fs::path dir = testing::scratch_directory("paired-errors");
  const auto error_of = [&](const std::string& body) { return study_file_error(dir, body); };
  std::string e = error_of(paired_study_text("  protocol: [P0, P1]", 4));
  EXPECT_NE(e.find("at least 3 conditions; the factors give 2"), std::string::npos) << e;
  e = error_of(paired_study_text("  step_nodes: [0, 300]\n  protocol: [P0, P1]", 1));
  EXPECT_NE(e.find("subjects"), std::string::npos) << e;
  EXPECT_NE(e.find("two subjects"), std::string::npos) << e;
  std::string text = paired_study_text("  step_nodes: [0, 300]\n  protocol: [P0, P1]", 4);
  text.replace(text.find("quality: finer"), 14, "quality: smoother");
  e = error_of(text);
  EXPECT_NE(e.find("quality"), std::string::npos) << e;
  EXPECT_NE(e.find("smoother"), std::string::npos) << e;
  text = paired_study_text("  step_nodes: [0, 300]\n  protocol: [P0, P1]", 4);
  text.replace(text.find("subjects: 4"), 11, "subjects: 4\n  labels: [a, b, c]");
  e = error_of(text);
  EXPECT_NE(e.find("5 labels, from +2 down to -2"), std::string::npos) << e;
  text = paired_study_text("  step_nodes: [0, 300]\n  protocol: [P0, P1]", 4);
  text.replace(text.find("subjects: 4"), 11, "subjects: 4\n  switch_button: 0");
  e = error_of(text);
  EXPECT_NE(e.find("switch_button"), std::string::npos) << e;
  EXPECT_NE(e.find("simulated subjects press no button"), std::string::npos) << e;
}

TEST(PairedComparisonStudyFile, EverySubjectMeetsEveryPairOnceInABalancedOrder) {
  constexpr int kConditions = 4, kSubjects = 6;
  const std::vector<PresentedPair> plan = presentation_plan(kConditions, kSubjects);
  ASSERT_EQ(plan.size(), static_cast<std::size_t>(kSubjects * 6));
  std::map<std::pair<int, int>, int> presented;       // (first, second) -> subjects
  std::map<std::pair<int, int>, int> first_position;  // (low, high) -> subjects that met it first
  for (int subject = 0; subject < kSubjects; ++subject) {
    std::set<std::pair<int, int>> met;
    for (const PresentedPair& pair : plan) {
      if (pair.subject != subject) continue;
      EXPECT_NE(pair.first, pair.second);
      met.emplace(std::min(pair.first, pair.second), std::max(pair.first, pair.second));
      ++presented[{pair.first, pair.second}];
      if (pair.position == 0)
        ++first_position[{std::min(pair.first, pair.second), std::max(pair.first, pair.second)}];
    }
    EXPECT_EQ(met.size(), 6u) << "subject " << subject << " meets every pair once";
  }
  // Each pair is presented each way round by half the subjects.
  for (int i = 0; i < kConditions; ++i)
    for (int j = i + 1; j < kConditions; ++j) {
      EXPECT_EQ((presented[{i, j}]), kSubjects / 2) << i << " first, then " << j;
      EXPECT_EQ((presented[{j, i}]), kSubjects / 2) << j << " first, then " << i;
    }
  // Not the same pair first for everyone.
  EXPECT_GT(first_position.size(), 1u);
}

// With 150 nodes held P0's force changes only at the slowed simulation's rate, P1's at every
// haptic tick: simulated subjects, rating from the trials' measures, find P1 finer, and
// Scheffe's analysis says so beyond its 5 % yardstick.
TEST(PairedComparisonStudy,
     SimulatedSubjectsRateEveryPairOnceAndTheAnalysisFindsP1FinerUnderStepDelay) {
  const fs::path dir = testing::scratch_directory("paired-run");
  constexpr int kSubjects = 4;
  write_study_files(dir,
                    paired_study_text("  step_nodes: [0, 150]\n  protocol: [P0, P1]", kSubjects));
  StudyRunOptions options;
  options.out = dir / "out";
  options.server_program = testing::server_program();
  options.client_program = testing::client_program();
  ASSERT_EQ(run_study(dir / "study.yaml", options), 0);

  const auto ratings = testing::read_csv_table(options.out / "ratings.csv");
  ASSERT_EQ(ratings.size(), static_cast<std::size_t>(kSubjects * 6));
  for (const auto& row : ratings) {
    const int rating = std::stoi(row.at("rating"));
    EXPECT_GE(rating, -2);
    EXPECT_LE(rating, 2);
    EXPECT_EQ(row.at("rated_by"), "simulated");
  }
  std::map<std::string, double> scale;
  for (const auto& row : testing::read_csv_table(options.out / "analysis" / "scale.csv"))
    scale[row.at("condition")] = std::stod(row.at("scale_value"));
  ASSERT_EQ(scale.size(), 4u);
  double sum = 0;
  for (const auto& [name, value] : scale) sum += value;
  EXPECT_NEAR(sum, 0, 1e-12);
  double yardstick_05 = 0;
  for (const auto& row : testing::read_csv_table(options.out / "analysis" / "yardsticks.csv"))
    if (std::stod(row.at("level")) == 0.05) yardstick_05 = std::stod(row.at("yardstick"));
  ASSERT_GT(yardstick_05, 0);
  std::printf("  scale values: T0-P0 %.3f, T0-P1 %.3f, T150-P0 %.3f, T150-P1 %.3f; Y(0.05) %.3f\n",
              scale.at("S0-T0-P0"), scale.at("S0-T0-P1"), scale.at("S0-T150-P0"),
              scale.at("S0-T150-P1"), yardstick_05);
  EXPECT_GT(scale.at("S0-T150-P1") - scale.at("S0-T150-P0"), yardstick_05);
  bool found = false;
  for (const auto& row : testing::read_csv_table(options.out / "analysis" / "differences.csv"))
    if ((row.at("first") == "S0-T150-P0" && row.at("second") == "S0-T150-P1") ||
        (row.at("first") == "S0-T150-P1" && row.at("second") == "S0-T150-P0")) {
      found = true;
      EXPECT_EQ(row.at("significant_05"), "yes");
    }
  EXPECT_TRUE(found);
  for (const char* file : {"analysis/anova.csv", "analysis/table.txt", "figures/scale.svg"})
    EXPECT_TRUE(fs::exists(options.out / file)) << file;
}

// A study rated by people: no simulated participants, a pair served per session; `extra`:
// further keys of its paired_comparison block.
std::string person_study_text(int subjects, const std::string& extra = "") {
  return fmt::format(R"(name: people
scene: cube.yaml
condensation: naive
factors:
  step_nodes: [0, 150]
  protocol: [P0, P1]
paired_comparison:
  quality: finer
  subjects: {}
  practice_pairs: 1
  show_object: never
  pair_duration: 20
  rater: {{kind: person}}
{})",
                     subjects, extra);
}

// A study rated by people, rehearsed with a scripted subject at the terminal: a practice pair
// first (felt, not rated), then each pair in one session where the subject switches back and
// forth without being told which condition is which; a session stopped midway continues at
// the next unrated pair; once both subjects have rated every pair, the analysis. Each switch
// is in switches.csv and in the pair's server recording.
TEST(PairedComparisonStudy, PeopleRateEachPairSwitchingBlindAndAStoppedSessionContinues) {
  const fs::path dir = testing::scratch_directory("paired-people");
  write_study_files(dir, person_study_text(2));
  StudyRunOptions options;
  options.out = dir / "out";
  options.server_program = testing::server_program();
  options.client_program = testing::client_program();
  options.device = "script:" + (dir / "press.yaml").string();
  const auto session = [&](int subject, const std::string& commands) {
    std::istringstream in(commands);
    std::ostringstream out;
    options.subject = subject;
    options.input = &in;
    options.output = &out;
    EXPECT_EQ(run_study(dir / "study.yaml", options), 0) << out.str();
    return out.str();
  };
  EXPECT_NE(study_file_error(dir, person_study_text(2) + "participants: []\n")
                .find("has no simulated participants"),
            std::string::npos);
  write_study_files(dir, person_study_text(2));
  options.subject = 0;
  EXPECT_THROW(run_study(dir / "study.yaml", options), Error) << "no --subject";

  // Subject 1: practice (two switches, then on), two pairs rated, then stops.
  std::string said = session(1, "s\ns\nn\ns\n+1\n\ns\ns\n-2\n+2\ny\nq\n");
  EXPECT_NE(said.find("Practice pair 1 of 1 (not rated)"), std::string::npos) << said;
  EXPECT_NE(said.find("You are feeling: SECOND"), std::string::npos) << said;
  EXPECT_NE(said.find("stopped: run the same command again"), std::string::npos) << said;
  for (const char* secret : {"S0-T", "P0", "P1", "step", "150"})
    EXPECT_EQ(said.find(secret), std::string::npos)
        << "the terminal names no condition: " << secret << "\n"
        << said;
  auto ratings = testing::read_csv_table(options.out / "ratings.csv");
  ASSERT_EQ(ratings.size(), 2u);
  EXPECT_EQ(ratings[0].at("rating"), "1");
  EXPECT_EQ(ratings[1].at("rating"), "2") << "the grade confirmed, not the one replaced";
  EXPECT_EQ(ratings[1].at("rated_by"), "person");

  // Run again: no practice, the four pairs left; then subject 2 (practice, six pairs).
  said = session(1, "1\n\n0\n\ns\n-1\n\n2\ny\n");
  EXPECT_EQ(said.find("Practice"), std::string::npos) << said;
  EXPECT_NE(said.find("2 rated"), std::string::npos) << said;
  EXPECT_NE(said.find("6 of 12 ratings"), std::string::npos) << "the analysis waits for subject 2\n"
                                                             << said;
  said = session(2, "n\n1\n\n1\n\n1\n\ns\n1\n\n1\n\n1\n\n");
  EXPECT_NE(said.find("wrote"), std::string::npos) << said;
  ratings = testing::read_csv_table(options.out / "ratings.csv");
  EXPECT_EQ(ratings.size(), 12u);
  EXPECT_TRUE(fs::exists(options.out / "analysis" / "scale.csv"));
  EXPECT_TRUE(fs::exists(options.out / "figures" / "scale.svg"));

  // Every "s" is a switch, in switches.csv and in its pair's server recording.
  const auto switches = testing::read_csv_table(options.out / "switches.csv");
  EXPECT_EQ(switches.size(), 2u + 3u + 1u + 1u) << "practice 2, pairs 1 + 2, then 1, then 1";
  const record::Recording pair =
      record::read_recording(options.out / "pairs" / "s01-p01" / "server.mcap");
  std::vector<std::string> served;
  for (const record::SimulationStep& step : pair.steps)
    if (step.has_condition_switch()) served.push_back(step.condition_switch().name());
  EXPECT_EQ(served, (std::vector<std::string>{"second"}));
}

// A subject's lines, each after a pause: a person typing, not a script read at once.
class TypedLines : public std::streambuf {
 public:
  explicit TypedLines(std::vector<std::pair<std::chrono::milliseconds, std::string>> lines)
      : lines_(std::move(lines)) {}

 protected:
  int_type underflow() override {
    if (next_ == lines_.size()) return traits_type::eof();
    std::this_thread::sleep_for(lines_[next_].first);
    current_ = lines_[next_++].second + "\n";
    setg(current_.data(), current_.data(), current_.data() + current_.size());
    return traits_type::to_int_type(current_.front());
  }

 private:
  std::vector<std::pair<std::chrono::milliseconds, std::string>> lines_;
  std::size_t next_ = 0;
  std::string current_;
};

// Once the pair's time (pair_duration) is up its client has stopped: a switch is refused,
// saying so, and the subject rates (or goes on) with the server still there to ask.
TEST(PairedComparisonStudy, AfterThePairsTimeASwitchIsRefusedAndTheSubjectStillRates) {
  const fs::path dir = testing::scratch_directory("paired-time-up");
  std::string study = person_study_text(2);
  study.replace(study.find("pair_duration: 20"), 17, "pair_duration: 1");
  write_study_files(dir, study);
  StudyRunOptions options;
  options.out = dir / "out";
  options.server_program = testing::server_program();
  options.client_program = testing::client_program();
  options.device = "script:" + (dir / "press.yaml").string();
  options.subject = 1;
  using std::chrono::milliseconds;
  TypedLines typed({{milliseconds(0), "s"},
                    {milliseconds(1500), "s"},
                    {milliseconds(0), "n"},
                    {milliseconds(0), "+1"},
                    {milliseconds(0), "y"},
                    {milliseconds(0), "q"}});
  std::istream in(&typed);
  std::ostringstream out;
  options.input = &in;
  options.output = &out;
  ASSERT_EQ(run_study(dir / "study.yaml", options), 0) << out.str();
  EXPECT_NE(out.str().find("You are feeling: SECOND"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("The pair's time is up: go on to the next pair"), std::string::npos)
      << out.str();
  EXPECT_EQ(testing::read_csv_table(options.out / "switches.csv").size(), 1u)
      << "the late switch was not made";
  EXPECT_EQ(testing::read_csv_table(options.out / "ratings.csv").size(), 1u);
}

// The rating page in headless Chromium: the subject's hand on buttons and keys, the lab as
// its own process, and the device's button switching too. A practice pair, two pairs rated
// (by a click and by the arrow keys), a stop; run again, the four pairs left. The page never
// names a condition, follows the button, and what it sent is what ratings.csv holds; every
// switch, clicked or pressed, is in switches.csv and the pairs' server recordings.
TEST(PairedComparisonStudy, ASubjectRatesOnTheRatingPageInABrowserAndAStoppedSessionContinues) {
  if (const std::string why = testing::missing_browser(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = testing::scratch_directory("rating-page");
  write_study_files(dir, person_study_text(2, "  switch_button: 0\n"));
  // In every pair the subject presses and, 1.2 s in, presses the device's button once.
  std::ofstream(dir / "button.yaml") << R"(
units: mm
start: [4, 3, 4]
segments:
  - {move_to: [4, 3, 0.5], speed: 20}
  - {press: 0.75, speed: 0.75, direction: [0, 0, -1]}
  - {hold: 0.2, buttons: 1}
  - {release: 0.75, speed: 0.75}
)";
  const fs::path out = dir / "out";
  const auto session = [&](const std::string& name, const std::string& script) {
    ChildProcess lab(COHAPTIC_LAB_EXE,
                     {"study", (dir / "study.yaml").string(), "--out", out.string(), "--subject",
                      "1", "--device", "script:" + (dir / "button.yaml").string(), "--rating-page",
                      "127.0.0.1:0", "--server-program", testing::server_program(),
                      "--client-program", testing::client_program()},
                     dir / (name + "-lab.log"));
    EXPECT_TRUE(testing::wait_for_output(lab, "rating page at"));
    std::smatch match;
    const std::string log = lab.log_text();
    EXPECT_TRUE(std::regex_search(log, match, std::regex(R"(rating page at (http://\S+))"))) << log;
    ChildProcess node(
        testing::node_program(),
        {(fs::path(COHAPTIC_SOURCE_DIR) / "tests/support/rating_check.mjs").string(), "--url",
         match[1].str(), "--script", script, "--screenshot", (dir / (name + ".png")).string()},
        dir / (name + "-browser.log"));
    EXPECT_EQ(node.wait(std::chrono::minutes(5)), 0) << node.log_text();
    EXPECT_EQ(lab.wait(std::chrono::minutes(1)), 0) << lab.log_text();
    const std::string output = node.log_text();
    const nlohmann::json result =
        nlohmann::json::parse(output.substr(output.rfind("\n{\"") + 1), nullptr, false);
    EXPECT_FALSE(result.is_discarded()) << output;
    EXPECT_TRUE(result.value("errors", nlohmann::json::array()).empty()) << output;
    for (const auto& text : result.value("texts", nlohmann::json::array()))
      for (const char* secret : {"S0-T", "P0", "P1", "T150", "step"})
        EXPECT_EQ(text.get<std::string>().find(secret), std::string::npos)
            << "the page names no condition: " << text;
    return std::make_pair(result, lab.log_text());
  };

  // Each pair starts with the button's switch to SECOND. Practice: back by click, again by
  // key, then on; a pair rated 0 after choosing +1; a pair rated +2 by the arrow keys and
  // Enter; then a stop with a grade chosen.
  auto [first, log] =
      session("first",
              "await:second,switch,key-switch,key-next;"
              "await:second,switch,choose:+1,choose:0,screenshot,confirm;"
              "await:second,key-down,key-down,key-up,key-enter;await:second,choose:-2,stop");
  ASSERT_EQ(first["steps"].size(), 4u) << first.dump();
  EXPECT_EQ(first["steps"][0]["title"], "Practice pair 1 of 1 (not rated)");
  EXPECT_EQ(first["steps"][0]["screens"][1]["feeling"], "first");
  EXPECT_EQ(first["steps"][0]["screens"][2]["feeling"], "second");
  EXPECT_EQ(first["steps"][1]["screens"][1]["feeling"], "first");
  EXPECT_EQ(first["steps"][1]["screens"][3]["chosen_grade"], 0);
  EXPECT_NE(first["final"]["note"].get<std::string>().find("Stopped"), std::string::npos)
      << first.dump();
  EXPECT_NE(log.find("(rating page)"), std::string::npos)
      << "the terminal logs the page's commands\n"
      << log;
  EXPECT_NE(log.find("(button) You are feeling: SECOND"), std::string::npos) << log;
  auto ratings = testing::read_csv_table(out / "ratings.csv");
  ASSERT_EQ(ratings.size(), 2u);
  EXPECT_EQ(ratings[0].at("rating"), "0");
  EXPECT_EQ(ratings[1].at("rating"), "2");

  // Again: no practice, pairs 3 to 6; the analysis waits for subject 2.
  auto [second, second_log] =
      session("second",
              "await:second,choose:-1,confirm;await:second,switch,choose:+1,confirm;"
              "await:second,choose:+2,confirm;await:second,key-up,key-enter");
  ASSERT_EQ(second["steps"].size(), 4u) << second.dump();
  EXPECT_EQ(second["steps"][0]["title"], "Pair 3 of 6");
  EXPECT_NE(second["final"]["note"].get<std::string>().find("Every pair is rated"),
            std::string::npos)
      << second.dump();
  EXPECT_EQ(second["final"]["rated"], 6);
  ratings = testing::read_csv_table(out / "ratings.csv");
  ASSERT_EQ(ratings.size(), 6u);
  const std::vector<std::string> expected = {"0", "2", "-1", "1", "2", "-2"};
  for (std::size_t k = 0; k < expected.size(); ++k)
    EXPECT_EQ(ratings[k].at("rating"), expected[k]) << k;
  EXPECT_NE(second_log.find("6 of 12 ratings"), std::string::npos) << second_log;

  // Every switch, pressed or clicked: the button's in each of the 8 pairs served (pair 3
  // twice), and 2 + 1 + 1 clicks or keys. Pair 1: the button's, then the click's.
  const auto switches = testing::read_csv_table(out / "switches.csv");
  EXPECT_EQ(switches.size(), 8u + 4u);
  std::vector<std::string> pair_1;
  for (const auto& row : switches)
    if (row.at("pair") == "1") pair_1.push_back(row.at("serving"));
  EXPECT_EQ(pair_1, (std::vector<std::string>{"second", "first"}));
  const record::Recording pair = record::read_recording(out / "pairs" / "s01-p01" / "server.mcap");
  std::vector<std::string> served;
  for (const record::SimulationStep& step : pair.steps)
    if (step.has_condition_switch()) served.push_back(step.condition_switch().name());
  EXPECT_EQ(served, pair_1);
}

}  // namespace
}  // namespace cohaptic
