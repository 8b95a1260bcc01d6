#include "lab/paired_comparison_study.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <random>
#include <stdexcept>

#include "common/study/paired_comparison_analysis.h"
#include "common/study/paired_comparison_report.h"
#include "common/util/atomic_file.h"
#include "common/util/csv.h"
#include "common/util/error.h"

namespace cohaptic {

namespace {

constexpr std::array<const char*, 6> kRatingColumns = {"subject", "position", "first",
                                                       "second",  "rating",   "rated_by"};

// The default labels: "first clearly finer", "first slightly finer", "no difference", ...
std::vector<std::string> default_labels(RatedQuality quality, int grades) {
  const std::string more = to_string(quality);
  std::vector<std::string> labels;
  for (int grade = grades; grade >= -grades; --grade) {
    if (grade == 0) {
      labels.emplace_back("no difference");
      continue;
    }
    const char* how = std::abs(grade) == grades ? "clearly"
                      : std::abs(grade) == 1    ? "slightly"
                                                : "rather";
    labels.push_back(fmt::format("{} {} {}", grade > 0 ? "first" : "second", how, more));
  }
  return labels;
}

}  // namespace

PairedComparisonDesign parse_paired_comparison(const YamlCursor& block) {
  block.only_keys({"question", "quality", "grades", "labels", "subjects", "rater", "practice_pairs",
                   "show_object", "pair_duration", "switch_button"});
  PairedComparisonDesign design;
  design.quality = parse_rated_quality(block.at("quality").choice({"finer", "harder"}));
  design.question = block.find("question")
                        ? block.at("question").text()
                        : fmt::format("Which felt {}?", to_string(design.quality));
  if (auto grades = block.find("grades")) {
    const std::int64_t n = grades->integer();
    if (n < 1 || n > 5)
      grades->fail("an integer from 1 to 5 (the scale runs from -grades to +grades)");
    design.grades = static_cast<int>(n);
  }
  design.labels = default_labels(design.quality, design.grades);
  if (auto labels = block.find("labels")) {
    const std::vector<YamlCursor> items = labels->items();
    if (items.size() != design.labels.size())
      labels->fail(fmt::format("{} labels, from +{} down to -{}", design.labels.size(),
                               design.grades, design.grades));
    for (std::size_t i = 0; i < items.size(); ++i) design.labels[i] = items[i].text();
  }
  if (auto subjects = block.find("subjects")) {
    const std::int64_t n = subjects->integer();
    if (n < 2 || n > 1000)
      subjects->fail("an integer from 2 to 1000 (Scheffe's analysis needs two subjects)");
    design.subjects = static_cast<int>(n);
  }
  design.rater = default_rater_settings(design.quality);
  design.rater.grades = design.grades;
  if (auto practice = block.find("practice_pairs")) {
    const std::int64_t n = practice->integer();
    if (n < 0 || n > 100) practice->fail("an integer from 0 to 100");
    design.practice_pairs = static_cast<int>(n);
  }
  if (auto shown = block.find("show_object"))
    design.show_object = shown->choice({"practice", "always", "never"});
  if (auto duration = block.find("pair_duration"))
    design.pair_duration_s = duration->number_in(1, 3600, false, false, "seconds, 1 to 3600");
  if (auto button = block.find("switch_button")) {
    const std::int64_t n = button->integer();
    if (n < 0 || n > 31) button->fail("a device button, 0 to 31");
    design.switch_button = static_cast<int>(n);
  }
  if (auto rater = block.find("rater")) {
    rater->only_keys({"kind", "jnd", "noise", "seed"});
    if (auto kind = rater->find("kind"))
      design.rater_kind = kind->choice({"simulated", "person"}) == "person" ? RaterKind::person
                                                                            : RaterKind::simulated;
    if (auto jnd = rater->find("jnd"))
      design.rater.just_noticeable_difference =
          jnd->number_in(0, 10, false, false, "a Weber fraction above 0");
    if (auto noise = rater->find("noise"))
      design.rater.noise_sd =
          noise->number_in(0, 100, false, false, "a standard deviation >= 0, in JNDs");
    if (auto seed = rater->find("seed")) design.rater.seed = static_cast<unsigned>(seed->integer());
  }
  if (design.switch_button >= 0 && design.rater_kind != RaterKind::person)
    block.at("switch_button")
        .fail(
            "a key of a study rated by people (rater: {kind: person}): simulated subjects press no "
            "button");
  return design;
}

std::vector<PresentedPair> presentation_plan(int conditions, int subjects) {
  const int pairs = pair_count(conditions);
  std::vector<std::pair<int, int>> base;
  for (int i = 0; i < conditions; ++i)
    for (int j = i + 1; j < conditions; ++j) base.emplace_back(i, j);
  std::vector<PresentedPair> plan;
  for (int l = 0; l < subjects; ++l) {
    const int offset = l * pairs / subjects;
    for (int position = 0; position < pairs; ++position) {
      const int k = (position + offset) % pairs;
      const auto [low, high] = base[static_cast<std::size_t>(k)];
      const bool low_first = (l + k) % 2 == 0;
      plan.push_back({l, position, low_first ? low : high, low_first ? high : low});
    }
  }
  return plan;
}

void write_pair_plan(const std::filesystem::path& file,
                     const std::vector<std::string>& condition_names, int subjects) {
  AtomicFile csv(file);
  csv.write("subject,position,first,second\n");
  for (const PresentedPair& pair :
       presentation_plan(static_cast<int>(condition_names.size()), subjects))
    csv.print("{},{},{},{}\n", pair.subject + 1, pair.position + 1,
              csv_field(condition_names[static_cast<std::size_t>(pair.first)]),
              csv_field(condition_names[static_cast<std::size_t>(pair.second)]));
  csv.commit();
}

std::vector<PairRatingRow> read_ratings(const std::filesystem::path& file) {
  std::vector<PairRatingRow> rows;
  if (!std::filesystem::exists(file)) return rows;
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  if (split_csv_line(line) !=
      std::vector<std::string>(kRatingColumns.begin(), kRatingColumns.end()))
    throw Error(fmt::format("{}: not a ratings table (its header is '{}')", file.string(), line));
  for (int number = 2; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    const std::vector<std::string> fields = split_csv_line(line);
    try {
      if (fields.size() != kRatingColumns.size()) throw std::invalid_argument("field count");
      rows.push_back({std::stoi(fields[0]), std::stoi(fields[1]), fields[2], fields[3],
                      std::stoi(fields[4]), fields[5]});
    } catch (const std::exception&) {
      throw Error(fmt::format("{}:{}: not a row of {} fields: {}", file.string(), number,
                              kRatingColumns.size(), line));
    }
  }
  return rows;
}

void write_ratings(const std::filesystem::path& file, const std::vector<PairRatingRow>& rows) {
  AtomicFile csv(file);
  csv.print("{}\n", fmt::join(kRatingColumns, ","));
  for (const PairRatingRow& row : rows)
    csv.print("{},{},{},{},{},{}\n", row.subject, row.position, csv_field(row.first),
              csv_field(row.second), row.rating, row.rated_by);
  csv.commit();
}

std::vector<PairRatingRow> simulated_ratings(
    const PairedComparisonDesign& design, const std::vector<std::string>& condition_names,
    const std::vector<std::vector<TrialMeasures>>& measures) {
  if (measures.empty())
    throw Error("a paired-comparison study needs the measures of at least one repetition");
  std::vector<PairRatingRow> rows;
  std::mt19937 rng;
  int subject = -1;
  for (const PresentedPair& pair :
       presentation_plan(static_cast<int>(condition_names.size()), design.subjects)) {
    if (pair.subject != subject) {
      subject = pair.subject;
      rng.seed(design.rater.seed + static_cast<unsigned>(subject));
    }
    const std::vector<TrialMeasures>& felt =
        measures[static_cast<std::size_t>(subject) % measures.size()];
    const int rating = rate_pair(design.rater, felt[static_cast<std::size_t>(pair.first)],
                                 felt[static_cast<std::size_t>(pair.second)], rng);
    rows.push_back({subject + 1, pair.position + 1,
                    condition_names[static_cast<std::size_t>(pair.first)],
                    condition_names[static_cast<std::size_t>(pair.second)], rating, "simulated"});
  }
  return rows;
}

void analyse_ratings(const PairedComparisonDesign& design, const std::string& study_name,
                     const std::vector<std::string>& condition_names, const StudyFactors& factors,
                     const std::vector<PairRatingRow>& rows, const std::filesystem::path& out) {
  const int conditions = static_cast<int>(condition_names.size());
  if (conditions < 3)
    throw Error(fmt::format("a paired-comparison study needs at least 3 conditions (it has {})",
                            conditions));
  const auto index_of = [&](const std::string& name) {
    const auto at = std::find(condition_names.begin(), condition_names.end(), name);
    if (at == condition_names.end())
      throw Error(fmt::format("ratings.csv names a condition '{}' the study has not", name));
    return static_cast<int>(at - condition_names.begin());
  };
  PairedComparisonRatings ratings;
  ratings.conditions = conditions;
  ratings.ratings.assign(
      static_cast<std::size_t>(design.subjects),
      std::vector<double>(static_cast<std::size_t>(pair_count(conditions)), 0.0));
  std::vector<std::vector<char>> rated(
      static_cast<std::size_t>(design.subjects),
      std::vector<char>(static_cast<std::size_t>(pair_count(conditions)), 0));
  for (const PairRatingRow& row : rows) {
    if (row.subject < 1 || row.subject > design.subjects)
      throw Error(fmt::format("ratings.csv: subject {} is not one of the study's 1 to {}",
                              row.subject, design.subjects));
    const int first = index_of(row.first), second = index_of(row.second);
    const int low = std::min(first, second), high = std::max(first, second);
    const auto s = static_cast<std::size_t>(row.subject - 1);
    const auto k = static_cast<std::size_t>(pair_index(low, high, conditions));
    if (rated[s][k])
      throw Error(fmt::format("ratings.csv: subject {} rated {} and {} twice", row.subject,
                              row.first, row.second));
    rated[s][k] = 1;
    // Nakaya's x_ij (i < j) is positive when i felt more: a pair presented the other way
    // round enters with its sign turned.
    ratings.ratings[s][k] = first == low ? row.rating : -row.rating;
  }
  for (std::size_t s = 0; s < rated.size(); ++s) {
    const auto missing = std::count(rated[s].begin(), rated[s].end(), 0);
    if (missing > 0)
      throw Error(fmt::format("subject {} has not rated {} of the {} pairs yet", s + 1, missing,
                              rated[s].size()));
  }

  const PairedComparisonAnalysis analysis = analyse_paired_comparisons(ratings);
  std::vector<FactorEffect> effects;
  if (factors.names.size() > 1)
    effects = factor_effects(analysis, factors.names, factors.level_count, factors.level_of);
  std::filesystem::create_directories(out / "analysis");
  write_analysis_csv(out / "analysis", analysis, condition_names, effects);
  const std::string table = format_analysis_table(analysis, condition_names, effects);
  AtomicFile text(out / "analysis" / "table.txt");
  text.write(table);
  text.commit();
  fmt::print("{}", table);

  ScaleLineFigure figure;
  figure.title =
      fmt::format("{}: Scheffe's paired comparisons, {} subjects ({})", study_name, design.subjects,
                  design.rater_kind == RaterKind::person ? "people" : "simulated");
  figure.question = fmt::format("{}  (a higher scale value: felt {})", design.question,
                                to_string(design.quality));
  figure.names = condition_names;
  figure.scale = analysis.scale;
  figure.yardstick_05 = analysis.yardstick_05;
  figure.yardstick_01 = analysis.yardstick_01;
  std::filesystem::create_directories(out / "figures");
  write_scale_line_svg(out / "figures" / "scale.svg", figure);
}

}  // namespace cohaptic
