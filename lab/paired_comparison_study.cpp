#include "lab/paired_comparison_study.h"

#include <fmt/format.h>

#include <random>

#include "common/study/paired_comparison_analysis.h"
#include "common/study/paired_comparison_report.h"
#include "common/util/atomic_file.h"
#include "common/util/csv.h"
#include "common/util/error.h"

namespace cohaptic {

namespace {

// The default labels: "first clearly finer", "first slightly finer", "no difference", ...
std::vector<std::string> default_labels(RatedQuality quality, int grades) {
  const std::string more = to_string(quality);
  std::vector<std::string> labels;
  for (int grade = grades; grade >= -grades; --grade) {
    if (grade == 0) {
      labels.emplace_back("no difference");
      continue;
    }
    const char* how = std::abs(grade) == grades ? "clearly" : std::abs(grade) == 1 ? "slightly" : "rather";
    labels.push_back(fmt::format("{} {} {}", grade > 0 ? "first" : "second", how, more));
  }
  return labels;
}

}  // namespace

PairedComparisonDesign parse_paired_comparison(const YamlCursor& block) {
  block.only_keys({"question", "quality", "grades", "labels", "subjects", "rater"});
  PairedComparisonDesign design;
  design.quality = parse_rated_quality(block.at("quality").choice({"finer", "harder"}));
  design.question = block.find("question") ? block.at("question").text()
                                           : fmt::format("Which felt {}?", to_string(design.quality));
  if (auto grades = block.find("grades")) {
    const std::int64_t n = grades->integer();
    if (n < 1 || n > 5) grades->fail("an integer from 1 to 5 (the scale runs from -grades to +grades)");
    design.grades = static_cast<int>(n);
  }
  design.labels = default_labels(design.quality, design.grades);
  if (auto labels = block.find("labels")) {
    const std::vector<YamlCursor> items = labels->items();
    if (items.size() != design.labels.size())
      labels->fail(fmt::format("{} labels, from +{} down to -{}", design.labels.size(), design.grades, design.grades));
    for (std::size_t i = 0; i < items.size(); ++i) design.labels[i] = items[i].text();
  }
  if (auto subjects = block.find("subjects")) {
    const std::int64_t n = subjects->integer();
    if (n < 2 || n > 1000) subjects->fail("an integer from 2 to 1000 (Scheffe's analysis needs two subjects)");
    design.subjects = static_cast<int>(n);
  }
  design.rater = default_rater_settings(design.quality);
  design.rater.grades = design.grades;
  if (auto rater = block.find("rater")) {
    rater->only_keys({"kind", "jnd", "noise", "seed"});
    if (auto kind = rater->find("kind")) kind->choice({"simulated"});
    if (auto jnd = rater->find("jnd"))
      design.rater.just_noticeable_difference = jnd->number_in(0, 10, false, false, "a Weber fraction above 0");
    if (auto noise = rater->find("noise"))
      design.rater.noise_sd = noise->number_in(0, 100, false, false, "a standard deviation >= 0, in JNDs");
    if (auto seed = rater->find("seed")) design.rater.seed = static_cast<unsigned>(seed->integer());
  }
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

void run_paired_comparisons(const PairedComparisonDesign& design, const std::string& study_name,
                            const std::vector<std::string>& condition_names, const StudyFactors& factors,
                            const std::vector<std::vector<TrialMeasures>>& measures, const std::filesystem::path& out) {
  const int conditions = static_cast<int>(condition_names.size());
  if (conditions < 3)
    throw Error(fmt::format("a paired-comparison study needs at least 3 conditions (it has {})", conditions));
  if (measures.empty()) throw Error("a paired-comparison study needs the measures of at least one repetition");

  PairedComparisonRatings ratings;
  ratings.conditions = conditions;
  ratings.ratings.assign(static_cast<std::size_t>(design.subjects),
                         std::vector<double>(static_cast<std::size_t>(pair_count(conditions)), 0.0));
  AtomicFile csv(out / "ratings.csv");
  csv.write("subject,position,first,second,rating,rated_by\n");
  std::mt19937 rng;
  int subject = -1;
  for (const PresentedPair& pair : presentation_plan(conditions, design.subjects)) {
    if (pair.subject != subject) {
      subject = pair.subject;
      rng.seed(design.rater.seed + static_cast<unsigned>(subject));
    }
    const std::vector<TrialMeasures>& felt = measures[static_cast<std::size_t>(subject) % measures.size()];
    const int rating = rate_pair(design.rater, felt[static_cast<std::size_t>(pair.first)],
                                 felt[static_cast<std::size_t>(pair.second)], rng);
    // Nakaya's x_ij (i < j) is positive when i felt more: a pair presented the other way round
    // enters with its sign turned.
    const int low = std::min(pair.first, pair.second), high = std::max(pair.first, pair.second);
    ratings.ratings[static_cast<std::size_t>(subject)][static_cast<std::size_t>(pair_index(low, high, conditions))] =
        pair.first == low ? rating : -rating;
    csv.print("{},{},{},{},{},simulated\n", subject + 1, pair.position + 1,
              csv_field(condition_names[static_cast<std::size_t>(pair.first)]),
              csv_field(condition_names[static_cast<std::size_t>(pair.second)]), rating);
  }
  csv.commit();

  const PairedComparisonAnalysis analysis = analyse_paired_comparisons(ratings);
  std::vector<FactorEffect> effects;
  if (factors.names.size() > 1) effects = factor_effects(analysis, factors.names, factors.level_count, factors.level_of);
  std::filesystem::create_directories(out / "analysis");
  write_analysis_csv(out / "analysis", analysis, condition_names, effects);
  const std::string table = format_analysis_table(analysis, condition_names, effects);
  AtomicFile text(out / "analysis" / "table.txt");
  text.write(table);
  text.commit();
  fmt::print("{}", table);

  ScaleLineFigure figure;
  figure.title = fmt::format("{}: Scheffe's paired comparisons, {} subjects (simulated)", study_name, design.subjects);
  figure.question = fmt::format("{}  (a higher scale value: felt {})", design.question, to_string(design.quality));
  figure.names = condition_names;
  figure.scale = analysis.scale;
  figure.yardstick_05 = analysis.yardstick_05;
  figure.yardstick_01 = analysis.yardstick_01;
  std::filesystem::create_directories(out / "figures");
  write_scale_line_svg(out / "figures" / "scale.svg", figure);
}

}  // namespace cohaptic
