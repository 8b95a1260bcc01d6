#include "lab/study.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <signal.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <functional>
#include <fstream>
#include <iostream>
#include <initializer_list>
#include <memory>
#include <optional>
#include <random>
#include <set>

#include "common/util/host_port.h"
#include "common/scene/load_scene.h"
#include "common/study/measures.h"
#include "common/study/paired_comparison_analysis.h"
#include "common/study/summary.h"
#include "common/study/svg_plot.h"
#include "common/util/atomic_file.h"
#include "common/util/csv.h"
#include "common/util/error.h"
#include "common/util/stopwatch.h"
#include "common/util/regular_file.h"
#include "common/util/yaml_cursor.h"
#include "common/util/child_process.h"
#include "lab/person_pairs.h"
#include "lab/rating_page.h"
#include "proto/record/recording.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic {
namespace {

using namespace std::chrono_literals;

std::string number(double v) { return fmt::format("{:g}", v); }

template <typename T>
std::vector<T> levels(const std::optional<YamlCursor>& cursor, T fallback,
                      T (*read)(const YamlCursor&)) {
  if (!cursor) return {fallback};
  std::vector<T> out;
  for (const YamlCursor& item : cursor->items()) out.push_back(read(item));
  if (out.empty()) cursor->fail("a non-empty list of levels");
  return out;
}

// Row r of a balanced (Williams) Latin square over n conditions: 0, 1, n-1, 2, n-2, ...
// shifted by r, so that every condition follows every other equally often.
std::vector<int> latin_square_row(int n, int r) {
  std::vector<int> row;
  for (int i = 0, low = 1, high = n - 1; i < n; ++i) {
    const int base = i == 0 ? 0 : (i % 2 == 1 ? low++ : high--);
    row.push_back((base + r) % n);
  }
  return row;
}

// The columns of trials.csv before the session fields: the trial and its factors.
const std::vector<std::string> kTrialColumns = {
    "trial",    "repetition", "condition", "participant", "protocol",
    "shift_ms", "jitter_ms",  "loss",      "step_nodes",  "sim_rate_hz"};

// The per-trial numbers after the factors and session fields: the measures, then the rates.
std::vector<std::string> value_columns() {
  std::vector<std::string> names;
  for (const NamedMeasure& m : named_measures(TrialMeasures{})) names.emplace_back(m.name);
  names.insert(names.end(), {"contact_sim_rate_hz", "server_sim_rate_hz", "fades", "fade_s"});
  return names;
}

ForceTrace trace_of(const record::Recording& recording) {
  ForceTrace trace;
  if (recording.ticks.empty()) return trace;
  const std::int64_t start = recording.ticks.front().time_ns();
  for (const record::HapticTick& tick : recording.ticks) {
    trace.time_s.push_back(static_cast<double>(tick.time_ns() - start) * 1e-9);
    trace.force.push_back(wire::from_wire(tick.force()));
    trace.position.push_back(wire::from_wire(tick.own()));
  }
  return trace;
}

std::filesystem::path program_beside(const std::string& relative) {
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe");
  return (self.parent_path() / relative).lexically_normal();
}

// The simulation's server steps per second, from its report.
// A figure of a process's JSON report, at `keys` (e.g. {"server", "sim_rate_hz"}); NaN,
// with a warning, when the report has none.
double report_figure(const std::filesystem::path& report_file,
                     std::initializer_list<const char*> keys) {
  try {
    nlohmann::json node = nlohmann::json::parse(read_text_file(report_file.string()));
    for (const char* key : keys) node = node.at(key);
    return node.get<double>();
  } catch (const std::exception& e) {
    spdlog::warn("no {} in {}: {}", fmt::join(keys, "."), report_file.string(), e.what());
    return std::nan("");
  }
}

// The simulation's step rate while `slot`'s tool pressed the object: the steps of the
// server's recording in which it pressed, over the time from each to the next step. This is
// the rate at which P0 can update the force the hand feels.
double contact_sim_rate_hz(const record::Recording& server, int slot) {
  std::size_t steps = 0;
  double time_s = 0;
  for (std::size_t k = 0; k + 1 < server.steps.size(); ++k) {
    const auto& pressing = server.steps[k].pressing_slots();
    if (std::find(pressing.begin(), pressing.end(), static_cast<std::uint32_t>(slot)) ==
        pressing.end())
      continue;
    ++steps;
    time_s += static_cast<double>(server.steps[k + 1].time_ns() - server.steps[k].time_ns()) * 1e-9;
  }
  return time_s > 0 ? static_cast<double>(steps) / time_s : std::nan("");
}

}  // namespace

std::string StudyCondition::name() const {
  std::string out = fmt::format("S{}-T{}-{}", number(shift_ms), step_nodes, protocol);
  if (jitter_ms > 0) out += "-J" + number(jitter_ms);
  if (loss > 0) out += "-L" + number(loss);
  if (sim_rate_hz > 0) out += "-R" + number(sim_rate_hz);
  return out;
}

Study load_study(const std::filesystem::path& file) {
  return parse_study(read_text_file(file.string()), file);
}

Study parse_study(const std::string& yaml_text, const std::filesystem::path& file) {
  const std::string name = file.string();
  const YamlCursor top(load_yaml(yaml_text, name), "", &name, 1);
  top.only_keys({"name", "scene", "trial_duration", "condensation", "participants", "factors",
                 "repetitions", "order", "session", "paired_comparison"});
  const std::filesystem::path base = file.has_parent_path() ? file.parent_path() : ".";
  Study study;
  study.file = file;
  study.name = top.find("name") ? top.at("name").text() : file.stem().string();
  const YamlCursor scene = top.at("scene");
  study.scene = base / scene.text();
  if (const auto why = why_not_a_regular_file(study.scene))
    scene.fail_message(fmt::format("scene file {} {}", study.scene.string(), *why));
  if (auto duration = top.find("trial_duration"))
    study.trial_duration_s = duration->number_in(0.5, 3600, false, false, "seconds, 0.5 to 3600");
  if (auto condensation = top.find("condensation"))
    study.condensation = condensation->choice({"naive", "incremental"});

  // A study rated by people has no simulated participants: the subject holds the device.
  if (auto paired = top.find("paired_comparison")) study.paired = parse_paired_comparison(*paired);
  const bool rated_by_people = study.paired && study.paired->rater_kind == RaterKind::person;
  if (rated_by_people) {
    if (auto participants = top.find("participants"))
      participants->fail_message(
          "a study rated by people has no simulated participants (the subject holds the device: "
          "cohaptic-lab study --subject N --device SPEC)");
  } else {
    for (const YamlCursor& item : top.at("participants").items()) {
      item.only_keys({"name", "device", "trajectory"});
      StudyParticipant p;
      p.name = item.at("name").text();
      p.device = item.find("device") ? item.at("device").choice({"hand", "script"}) : "hand";
      const YamlCursor trajectory = item.at("trajectory");
      p.trajectory = base / trajectory.text();
      if (const auto why = why_not_a_regular_file(p.trajectory))
        trajectory.fail_message(fmt::format("trajectory file {} {}", p.trajectory.string(), *why));
      p.slot = static_cast<int>(study.participants.size());
      study.participants.push_back(p);
    }
    if (study.participants.empty()) top.at("participants").fail("at least one participant");
    const std::size_t tools = load_scene(study.scene).tools.size();
    if (study.participants.size() > tools)
      top.at("participants")
          .fail_message(fmt::format(
              "{} participants, but the scene {} has {} tool(s): one participant holds one tool",
              study.participants.size(), study.scene.string(), tools));
  }
  const YamlCursor factors = top.at("factors");
  factors.only_keys({"shift_ms", "jitter_ms", "loss", "step_nodes", "sim_rate_hz", "protocol"});
  const auto non_negative = [](const YamlCursor& c) {
    return c.number_in(0, 1e6, false, false, "a number >= 0");
  };
  const auto probability = [](const YamlCursor& c) {
    return c.number_in(0, 1, false, true, "a probability in [0, 1)");
  };
  const auto nodes = [](const YamlCursor& c) {
    const std::int64_t n = c.integer();
    if (n < 0 || n > 100000) c.fail("a node count from 0 to 100000");
    return static_cast<int>(n);
  };
  const auto protocol = [](const YamlCursor& c) { return c.choice({"P0", "P1"}); };
  const auto shifts = levels<double>(factors.find("shift_ms"), 0.0, +non_negative);
  const auto jitters = levels<double>(factors.find("jitter_ms"), 0.0, +non_negative);
  const auto losses = levels<double>(factors.find("loss"), 0.0, +probability);
  const auto steps = levels<int>(factors.find("step_nodes"), 0, +nodes);
  const auto rates = levels<double>(factors.find("sim_rate_hz"), 0.0, +non_negative);
  const auto protocols =
      levels<std::string>(factors.find("protocol"), std::string("P1"), +protocol);
  for (double shift : shifts)
    for (int step : steps)
      for (const std::string& p : protocols)
        for (double jitter : jitters)
          for (double loss : losses)
            for (double rate : rates)
              study.conditions.push_back({shift, jitter, loss, rate, step, p});

  if (auto repetitions = top.find("repetitions")) {
    const std::int64_t n = repetitions->integer();
    if (n < 1 || n > 1000) repetitions->fail("an integer from 1 to 1000");
    study.repetitions = static_cast<int>(n);
  }
  if (auto order = top.find("order")) {
    order->only_keys({"kind", "seed"});
    study.order = order->at("kind").choice({"random", "latin_square", "sequential"});
    if (auto seed = order->find("seed")) study.seed = static_cast<unsigned>(seed->integer());
  }
  if (auto session = top.find("session"))
    for (const std::string& key : session->keys()) {
      const auto taken = [&](const std::vector<std::string>& names) {
        return std::find(names.begin(), names.end(), key) != names.end();
      };
      if (taken(kTrialColumns) || taken(value_columns()) || key == "status")
        session->at(key).fail_message(fmt::format(
            "'{}' is a column of trials.csv already: give the session field another name", key));
      study.session[key] = session->at(key).text();
    }

  if (auto paired = top.find("paired_comparison")) {
    if (study.conditions.size() < 3)
      paired->fail_message(
          fmt::format("a paired comparison needs at least 3 conditions; the factors give {}",
                      study.conditions.size()));
  }

  const int n = static_cast<int>(study.conditions.size());
  for (int rep = 1; rep <= study.repetitions; ++rep) {
    std::vector<int> order(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) order[i] = i;
    if (study.order == "random") {
      std::mt19937 rng(study.seed + static_cast<unsigned>(rep));
      std::shuffle(order.begin(), order.end(), rng);
    } else if (study.order == "latin_square") {
      order = latin_square_row(n, rep - 1);
    }
    for (int c : order)
      study.trials.push_back({static_cast<int>(study.trials.size()) + 1, rep, study.conditions[c]});
  }
  return study;
}

namespace {

std::size_t column_of(const std::vector<std::string>& header, const std::string& name) {
  const auto at = std::find(header.begin(), header.end(), name);
  if (at == header.end()) throw Error(fmt::format("no column {} in the trials table", name));
  return static_cast<std::size_t>(at - header.begin());
}

std::vector<std::string> header_of(const Study& study) {
  std::vector<std::string> header = kTrialColumns;
  for (const auto& [key, value] : study.session) header.push_back(key);
  for (const std::string& name : value_columns()) header.push_back(name);
  header.emplace_back("status");
  return header;
}

// The row of one participant in one trial: the factors, the session fields, the values (in
// value_columns() order) and the status.
std::vector<std::string> trial_row(const Study& study, const StudyTrial& trial,
                                   const StudyParticipant& participant,
                                   const std::vector<double>& values, const std::string& status) {
  const StudyCondition& c = trial.condition;
  std::vector<std::string> row = {std::to_string(trial.index),
                                  std::to_string(trial.repetition),
                                  c.name(),
                                  participant.name,
                                  c.protocol,
                                  number(c.shift_ms),
                                  number(c.jitter_ms),
                                  number(c.loss),
                                  std::to_string(c.step_nodes),
                                  number(c.sim_rate_hz)};
  for (const auto& [key, value] : study.session) row.push_back(value);
  for (double value : values) row.push_back(fmt::format("{:.9g}", value));
  row.push_back(status);
  return row;
}

// Runs one trial; returns one row per participant. Throws Error if a process cannot start.
std::vector<std::vector<std::string>> run_trial(const Study& study, const StudyTrial& trial,
                                                const StudyRunOptions& options,
                                                const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const StudyCondition& c = trial.condition;
  std::vector<std::string> server_args = {
      "--scene",          study.scene.string(),
      "--listen",         "127.0.0.1:0",
      "--protocol",       c.protocol,
      "--shift-delay-ms", number(c.shift_ms),
      "--jitter-ms",      number(c.jitter_ms),
      "--loss",           number(c.loss),
      "--seed",           std::to_string(study.seed + static_cast<unsigned>(trial.index)),
      "--step-nodes",     std::to_string(c.step_nodes),
      "--sim-rate-hz",    number(c.sim_rate_hz),
      "--condensation",   study.condensation,
      "--duration",       number(study.trial_duration_s + 30),
      "--record",         (dir / "server.mcap").string(),
      "--report",         (dir / "server.json").string()};
  ChildProcess server(options.server_program, server_args, dir / "server.log");
  if (!server.wait_for_log("listening on", 120s))
    throw Error(fmt::format("the server did not start (see {})", (dir / "server.log").string()));
  const int port = listening_port(server.log_text());
  std::vector<std::unique_ptr<ChildProcess>> clients;
  for (const StudyParticipant& p : study.participants)
    clients.push_back(std::make_unique<ChildProcess>(
        options.client_program,
        std::vector<std::string>{
            "--server", fmt::format("127.0.0.1:{}", port), "--user", p.name, "--slot",
            std::to_string(p.slot), "--device", p.device + ":" + p.trajectory.string(),
            "--duration", number(study.trial_duration_s), "--record",
            (dir / (p.name + ".mcap")).string(), "--report", (dir / (p.name + ".json")).string()},
        dir / (p.name + ".log")));
  std::string trial_status = "ok";
  for (std::size_t i = 0; i < clients.size(); ++i) {
    const auto exit = clients[i]->wait(
        std::chrono::milliseconds(static_cast<long>((study.trial_duration_s + 60) * 1000)));
    if (exit != 0)
      trial_status = fmt::format("client {} failed (see {})", study.participants[i].name,
                                 (dir / (study.participants[i].name + ".log")).string());
  }
  server.signal(SIGINT);
  if (server.wait(30s) != 0)
    trial_status = fmt::format("the server failed (see {})", (dir / "server.log").string());

  const double sim_rate_hz = report_figure(dir / "server.json", {"server", "sim_rate_hz"});
  std::optional<record::Recording> server_recording;
  try {
    server_recording = record::read_recording(dir / "server.mcap");
  } catch (const Error& e) {
    trial_status = fmt::format("the server's recording is unreadable: {}", e.what());
  }
  std::vector<std::vector<std::string>> rows;
  for (const StudyParticipant& p : study.participants) {
    std::vector<double> values(value_columns().size(), std::nan(""));
    std::string status = trial_status;
    try {
      std::vector<double> measured;
      for (const NamedMeasure& m : named_measures(
               measure_trial(trace_of(record::read_recording(dir / (p.name + ".mcap"))))))
        measured.push_back(m.value);
      measured.push_back(server_recording ? contact_sim_rate_hz(*server_recording, p.slot)
                                          : std::nan(""));
      measured.push_back(sim_rate_hz);
      // The fades the participant felt: a trial the machine could not keep up with shows them.
      measured.push_back(report_figure(dir / (p.name + ".json"), {"fades", "count"}));
      measured.push_back(report_figure(dir / (p.name + ".json"), {"fades", "total_s"}));
      values = std::move(measured);
    } catch (const Error& e) {
      status = fmt::format("no measures: {}", e.what());
    }
    rows.push_back(trial_row(study, trial, p, values, status));
  }
  return rows;
}

void write_rows(const std::filesystem::path& file, const std::vector<std::string>& header,
                const std::vector<std::vector<std::string>>& rows) {
  AtomicFile out(file);
  const auto line = [&out](const std::vector<std::string>& fields) {
    for (std::size_t i = 0; i < fields.size(); ++i)
      out.print("{}{}", i ? "," : "", csv_field(fields[i]));
    out.write("\n");
  };
  line(header);
  for (const auto& row : rows) line(row);
  out.commit();
}

// The paper's Fig. 4 and one chart per measure.
void write_figures(const Study& study, const std::filesystem::path& out,
                   const std::vector<std::string>& header,
                   const std::vector<std::vector<std::string>>& rows) {
  const std::filesystem::path figures = out / "figures";
  std::filesystem::create_directories(figures);
  // Fig. 4: each condition's longest stroke (first participant, first repetition: a whole
  // press, where a bouncing hand has short ones too), normalised by its peak, against time
  // since the stroke began.
  LinePlot fig4;
  fig4.title =
      fmt::format("{}: reaction force in a stroke, normalised (the paper's Fig. 4)", study.name);
  fig4.x_label = "time since the stroke began (s)";
  fig4.y_label = "force / peak force";
  std::set<std::string> done;
  for (const StudyTrial& trial : study.trials) {
    const std::string name = trial.condition.name();
    if (done.count(name)) continue;
    const std::filesystem::path file = out / "trials" / fmt::format("{:03d}", trial.index) /
                                       (study.participants.front().name + ".mcap");
    if (!std::filesystem::exists(file)) continue;
    done.insert(name);
    const ForceTrace trace = trace_of(record::read_recording(file));
    const std::vector<Stroke> strokes = find_strokes(trace);
    if (strokes.empty()) continue;
    const Stroke& stroke =
        *std::max_element(strokes.begin(), strokes.end(), [&](const Stroke& a, const Stroke& b) {
          return trace.time_s[a.end - 1] - trace.time_s[a.begin] <
                 trace.time_s[b.end - 1] - trace.time_s[b.begin];
        });
    double peak = 0;
    for (std::size_t k = stroke.begin; k < stroke.end; ++k)
      peak = std::max(peak, trace.force[k].norm());
    Series series;
    series.label = name;
    for (std::size_t k = stroke.begin; k < stroke.end; ++k) {
      series.x.push_back(trace.time_s[k] - trace.time_s[stroke.begin]);
      series.y.push_back(peak > 0 ? trace.force[k].norm() / peak : 0);
    }
    fig4.series.push_back(std::move(series));
  }
  write_svg(figures / "fig4.svg", fig4);

  // Each measure: mean +- sd per condition.
  const auto column = [&](const std::string& name) { return column_of(header, name); };
  for (const std::string& measure : value_columns()) {
    if (measure == "duration_s" || measure == "contact_time_s") continue;
    BarChart chart;
    chart.title = fmt::format("{}: {} per condition (mean +- sd over trials and participants)",
                              study.name, measure);
    chart.x_label = "condition";
    chart.y_label = measure;
    for (const StudyCondition& condition : study.conditions) {
      std::vector<double> values;
      for (const auto& row : rows)
        if (row[column("condition")] == condition.name() && row[column("status")] == "ok")
          values.push_back(std::stod(row[column(measure)]));
      const Statistics s = describe(values);
      chart.bars.push_back(
          {condition.name(), s.n ? s.mean : std::nan(""), s.n > 1 ? s.sd : 0.0, ""});
    }
    write_svg(figures / (measure + ".svg"), chart);
  }
}

// The factors that vary across the conditions (a full factorial: parse_study makes every
// combination), each condition's level of each.
StudyFactors factors_of(const std::vector<StudyCondition>& conditions) {
  const std::vector<std::pair<std::string, std::function<std::string(const StudyCondition&)>>>
      fields = {
          {"shift_ms", [](const StudyCondition& c) { return number(c.shift_ms); }},
          {"jitter_ms", [](const StudyCondition& c) { return number(c.jitter_ms); }},
          {"loss", [](const StudyCondition& c) { return number(c.loss); }},
          {"step_nodes", [](const StudyCondition& c) { return std::to_string(c.step_nodes); }},
          {"sim_rate_hz", [](const StudyCondition& c) { return number(c.sim_rate_hz); }},
          {"protocol", [](const StudyCondition& c) { return c.protocol; }}};
  StudyFactors factors;
  factors.level_of.resize(conditions.size());
  for (const auto& [name, level_text] : fields) {
    std::vector<std::string> levels;
    std::vector<int> level_of;
    for (const StudyCondition& condition : conditions) {
      const std::string text = level_text(condition);
      auto at = std::find(levels.begin(), levels.end(), text);
      if (at == levels.end()) at = levels.insert(levels.end(), text);
      level_of.push_back(static_cast<int>(at - levels.begin()));
    }
    if (levels.size() < 2) continue;
    factors.names.push_back(name);
    factors.level_count.push_back(static_cast<int>(levels.size()));
    for (std::size_t c = 0; c < conditions.size(); ++c) factors.level_of[c].push_back(level_of[c]);
  }
  return factors;
}

// measures[r][c]: condition c's measures in repetition r + 1, from the first participant's
// rows of trials.csv (all ok: the caller has checked).
std::vector<std::vector<TrialMeasures>> measures_by_repetition(
    const Study& study, const std::vector<std::string>& header,
    const std::vector<std::vector<std::string>>& rows) {
  const auto column = [&](const std::string& name) { return column_of(header, name); };
  std::vector<std::vector<TrialMeasures>> measures(
      static_cast<std::size_t>(study.repetitions),
      std::vector<TrialMeasures>(study.conditions.size()));
  const std::string& participant = study.participants.front().name;
  for (const auto& row : rows) {
    if (row[column("participant")] != participant) continue;
    const auto condition =
        std::find_if(study.conditions.begin(), study.conditions.end(),
                     [&](const StudyCondition& c) { return c.name() == row[column("condition")]; });
    if (condition == study.conditions.end()) continue;
    measures[static_cast<std::size_t>(std::stoi(row[column("repetition")]) - 1)]
            [static_cast<std::size_t>(condition - study.conditions.begin())] = trial_measures_from(
                [&](std::string_view name) { return std::stod(row[column(std::string(name))]); });
  }
  return measures;
}

// The settings of a --condition of cohaptic-server for `c` (after "NAME:").
std::string condition_settings(const StudyCondition& c) {
  return fmt::format("protocol={},shift_ms={},jitter_ms={},loss={},step_nodes={},sim_rate_hz={}",
                     c.protocol, number(c.shift_ms), number(c.jitter_ms), number(c.loss),
                     c.step_nodes, number(c.sim_rate_hz));
}

// A study rated by people: one subject's unrated pairs, then the analysis if every subject
// has rated every pair.
int run_person_study(const Study& study, const StudyRunOptions& options) {
  if (options.subject == 0 || options.device.empty())
    throw Error(
        fmt::format("{} is rated by people, one subject at a time: give --subject N (1 to {}) and "
                    "--device SPEC "
                    "(the subject's device, as cohaptic-client --device takes it)",
                    study.file.string(), study.paired->subjects));
  PersonSessionSetup setup;
  setup.study_name = study.name;
  setup.scene = study.scene;
  setup.condensation = study.condensation;
  for (const StudyCondition& condition : study.conditions) {
    setup.condition_names.push_back(condition.name());
    setup.condition_settings.push_back(condition_settings(condition));
  }
  setup.design = *study.paired;
  setup.out = options.out;
  setup.server_program = options.server_program;
  setup.client_program = options.client_program;
  setup.subject = options.subject;
  setup.device = options.device;
  write_pair_plan(options.out / "pair_plan.csv", setup.condition_names, study.paired->subjects);
  std::ostream& out = options.output ? *options.output : std::cout;
  std::optional<RatingPage> page;
  if (!options.rating_page.empty()) {
    std::string host;
    std::uint16_t port = 0;
    if (const std::string problem = parse_host_port(options.rating_page, host, port, true);
        !problem.empty())
      throw Error("--rating-page: " + problem);
    page.emplace(host, port);
    out << fmt::format("rating page at {} (open it in a browser; the terminal only reports)\n",
                       page->url())
        << std::flush;
  }
  if (!run_person_pairs(setup, options.input ? *options.input : std::cin, out,
                        page ? &*page : nullptr)) {
    out << fmt::format(
        "stopped: run the same command again to continue with subject {}'s next pair\n",
        options.subject);
    return 0;
  }
  const std::vector<PairRatingRow> rows = read_ratings(options.out / "ratings.csv");
  const std::size_t expected = static_cast<std::size_t>(
      study.paired->subjects * pair_count(static_cast<int>(study.conditions.size())));
  if (rows.size() < expected) {
    out << fmt::format(
        "{} of {} ratings in {}: the analysis follows once every subject has rated every pair\n",
        rows.size(), expected, (options.out / "ratings.csv").string());
    return 0;
  }
  analyse_ratings(*study.paired, study.name, setup.condition_names, factors_of(study.conditions),
                  rows, options.out);
  out << fmt::format("wrote {} and {}\n", (options.out / "analysis").string(),
                     (options.out / "figures" / "scale.svg").string());
  return 0;
}

}  // namespace

int run_study(const std::filesystem::path& file, const StudyRunOptions& given) {
  const Study study = load_study(file);
  StudyRunOptions options = given;
  if (options.server_program.empty())
    options.server_program = program_beside("../server/cohaptic-server").string();
  if (options.client_program.empty())
    options.client_program = program_beside("../client/cohaptic-client").string();
  for (const auto& [program, option] : {std::pair{options.server_program, "--server-program"},
                                        std::pair{options.client_program, "--client-program"}})
    if (!std::filesystem::exists(program))
      throw Error(
          fmt::format("the program {} does not exist (build it, or give {})", program, option));
  std::filesystem::create_directories(options.out);
  if (study.paired && study.paired->rater_kind == RaterKind::person)
    return run_person_study(study, options);
  if (!options.rating_page.empty())
    throw Error(fmt::format(
        "--rating-page: {} is not rated by people (its paired_comparison rater is not person)",
        file.string()));

  // The plan: the trials in run order; a re-run must find the same plan.
  std::vector<std::vector<std::string>> plan;
  for (const StudyTrial& trial : study.trials)
    plan.push_back(
        {std::to_string(trial.index), std::to_string(trial.repetition), trial.condition.name()});
  const std::filesystem::path plan_file = options.out / "plan.csv";
  if (std::filesystem::exists(plan_file)) {
    std::ifstream in(plan_file);
    std::string line;
    std::getline(in, line);
    for (const auto& row : plan) {
      std::getline(in, line);
      if (split_csv_line(line) != row)
        throw Error(fmt::format(
            "{} belongs to a different study plan (trial {}): use a new --out directory",
            plan_file.string(), row[0]));
    }
  } else {
    write_rows(plan_file, {"trial", "repetition", "condition"}, plan);
  }

  // Trials already done: those whose every row has status ok; a failed trial runs again.
  const std::vector<std::string> header = header_of(study);
  const auto column = [&](const std::string& name) { return column_of(header, name); };
  std::vector<std::vector<std::string>> rows;
  const std::filesystem::path trials_file = options.out / "trials.csv";
  if (std::filesystem::exists(trials_file)) {
    std::ifstream in(trials_file);
    std::string line;
    std::getline(in, line);
    if (split_csv_line(line) != header)
      throw Error(
          fmt::format("{} has other columns than this study writes: use a new --out directory",
                      trials_file.string()));
    for (int number = 2; std::getline(in, line); ++number)
      if (!line.empty()) {
        rows.push_back(split_csv_line(line));
        if (rows.back().size() != header.size())
          throw Error(fmt::format("{}:{}: {} fields where the header has {}", trials_file.string(),
                                  number, rows.back().size(), header.size()));
      }
  }
  std::set<std::string> failed;
  for (const auto& row : rows)
    if (row[column("status")] != "ok") failed.insert(row[column("trial")]);
  std::erase_if(rows, [&](const auto& row) { return failed.count(row[column("trial")]) > 0; });
  std::set<int> completed;
  for (const auto& row : rows) completed.insert(std::stoi(row[column("trial")]));
  const std::size_t total = study.trials.size();
  fmt::print(
      "study '{}': {} conditions x {} repetitions = {} trials of {:g} s, {} participant(s); {} "
      "already done{}\n",
      study.name, study.conditions.size(), study.repetitions, total, study.trial_duration_s,
      study.participants.size(), completed.size(),
      failed.empty() ? "" : fmt::format(", {} that failed will run again", failed.size()));
  for (const StudyTrial& trial : study.trials) {
    if (completed.count(trial.index)) continue;
    Stopwatch watch;
    fmt::print("[{}/{}] {} (repetition {}) ... ", trial.index, total, trial.condition.name(),
               trial.repetition);
    std::fflush(stdout);
    std::vector<std::vector<std::string>> trial_rows;
    try {
      trial_rows = run_trial(study, trial, options,
                             options.out / "trials" / fmt::format("{:03d}", trial.index));
    } catch (const Error& e) {
      for (const StudyParticipant& p : study.participants)
        trial_rows.push_back(trial_row(study, trial, p,
                                       std::vector<double>(value_columns().size(), std::nan("")),
                                       fmt::format("error: {}", e.what())));
    }
    const auto value = [&](const char* name) {
      return std::stod(trial_rows.front()[column(name)]);
    };
    const std::string faded =
        value("fades") > 0
            ? fmt::format(", the force faded {:.0f}x ({:.0f} ms: the machine did not keep up)",
                          value("fades"), value("fade_s") * 1e3)
            : "";
    fmt::print(
        "{:.1f} s: force updates {:.0f}/s (simulation {:.0f}/s in contact), terminal force ratio "
        "{:.3f}, "
        "peak {:.2f} N{}, {}\n",
        watch.elapsed_ms() / 1000, value("force_update_rate_hz"), value("contact_sim_rate_hz"),
        value("terminal_force_ratio"), value("peak_force_n"), faded, trial_rows.front().back());
    rows.insert(rows.end(), trial_rows.begin(), trial_rows.end());
    write_rows(trials_file, header, rows);  // after every trial: an interruption loses at most one
  }

  std::vector<ConditionTrial> trials;
  std::set<std::string> failed_now;
  for (const auto& row : rows) {
    if (row[column("status")] != "ok") {
      failed_now.insert(row[column("trial")]);
      continue;
    }
    ConditionTrial& trial = trials.emplace_back();
    trial.condition = row[column("condition")];
    for (const std::string& name : value_columns())
      trial.values.push_back({name, std::stod(row[column(name)])});
  }
  write_summary_csv(options.out / "summary.csv", summarize(trials));
  write_figures(study, options.out, header, rows);
  fmt::print("wrote {}, {} and {}\n", trials_file.string(), (options.out / "summary.csv").string(),
             (options.out / "figures").string());
  if (study.paired && failed_now.empty()) {
    std::vector<std::string> names;
    for (const StudyCondition& condition : study.conditions) names.push_back(condition.name());
    write_pair_plan(options.out / "pair_plan.csv", names, study.paired->subjects);
    write_ratings(
        options.out / "ratings.csv",
        simulated_ratings(*study.paired, names, measures_by_repetition(study, header, rows)));
    analyse_ratings(*study.paired, study.name, names, factors_of(study.conditions),
                    read_ratings(options.out / "ratings.csv"), options.out);
    fmt::print("wrote {}, {} and {}\n", (options.out / "ratings.csv").string(),
               (options.out / "analysis").string(),
               (options.out / "figures" / "scale.svg").string());
  }
  if (failed_now.empty()) return 0;
  fmt::print(
      stderr,
      "{} trial(s) failed (their status in {} says why): run the study again to retry them\n",
      failed_now.size(), trials_file.string());
  return 1;
}

LabCommand add_study_command(CLI::App& lab) {
  struct StudyCommandLine {
    std::filesystem::path file;
    StudyRunOptions options;
  };
  auto line = std::make_shared<StudyCommandLine>();
  CLI::App* command = lab.add_subcommand("study",
                                         "Run a lab study: every trial with real server and client "
                                         "processes, recorded; trials.csv, summary.csv "
                                         "and figures in --out (re-run to continue an interrupted "
                                         "study); with a paired_comparison block, the "
                                         "pairs rated by simulated subjects, or by a person "
                                         "(--subject, --device) at the terminal, and Scheffe's "
                                         "analysis");
  command->add_option("file", line->file, "The study file (YAML)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--out", line->options.out, "Output directory")->required();
  command->add_option("--server-program", line->options.server_program,
                      "cohaptic-server to run (default: the one of this build)");
  command->add_option("--client-program", line->options.client_program,
                      "cohaptic-client to run (default: the one of this build)");
  command
      ->add_option("--subject", line->options.subject,
                   "A study rated by people: the subject (1, 2, ...) who sits now; their unrated "
                   "pairs are served")
      ->check(CLI::PositiveNumber);
  command->add_option(
      "--device", line->options.device,
      "A study rated by people: the subject's haptic device, as cohaptic-client --device takes it");
  command->add_option(
      "--rating-page", line->options.rating_page,
      "A study rated by people: serve the rating page at HOST:PORT (port 0: any free port; off "
      "loopback a token is printed in its address) and take the subject's commands from it, not "
      "from "
      "the terminal");
  return {command, [line] { return run_study(line->file, line->options); }};
}

}  // namespace cohaptic
