#include "common/study/summary.h"

#include <fmt/format.h>

#include <cmath>
#include <map>

#include "common/util/atomic_file.h"
#include "common/util/csv.h"
#include "common/util/not_a_number.h"

namespace cohaptic {

Statistics describe(std::span<const double> values) {
  Statistics s;
  double sum = 0;
  for (double v : values)
    if (std::isfinite(v)) {
      sum += v;
      ++s.n;
    }
  if (s.n == 0) return {kNaN, kNaN, 0};
  s.mean = sum / static_cast<double>(s.n);
  if (s.n < 2) {
    s.sd = kNaN;
    return s;
  }
  double sum_sq = 0;
  for (double v : values)
    if (std::isfinite(v)) sum_sq += (v - s.mean) * (v - s.mean);
  s.sd = std::sqrt(sum_sq / static_cast<double>(s.n - 1));
  return s;
}

ConditionTrial condition_trial(std::string condition, const TrialMeasures& measures) {
  ConditionTrial trial{std::move(condition), {}};
  for (const NamedMeasure& named : named_measures(measures))
    trial.values.push_back({std::string(named.name), named.value});
  return trial;
}

std::vector<ConditionSummary> summarize(const std::vector<ConditionTrial>& trials) {
  // Conditions and names in order of first appearance; values[c][m] = value m over the
  // trials of condition c.
  std::vector<std::string> conditions, names;
  std::map<std::string, std::size_t> condition_index, name_index;
  std::vector<std::vector<std::vector<double>>> values;
  for (const ConditionTrial& trial : trials)
    for (const TrialValue& value : trial.values)
      if (name_index.try_emplace(value.name, names.size()).second) names.push_back(value.name);
  for (const ConditionTrial& trial : trials) {
    const auto [it, inserted] = condition_index.try_emplace(trial.condition, conditions.size());
    if (inserted) {
      conditions.push_back(trial.condition);
      values.emplace_back(names.size());
    }
    for (const TrialValue& value : trial.values)
      values[it->second][name_index.at(value.name)].push_back(value.value);
  }
  std::vector<ConditionSummary> summary;
  summary.reserve(conditions.size() * names.size());
  for (std::size_t c = 0; c < conditions.size(); ++c)
    for (std::size_t m = 0; m < names.size(); ++m) {
      const Statistics s = describe(values[c][m]);
      summary.push_back({conditions[c], names[m], s.mean, s.sd, s.n});
    }
  return summary;
}

void write_summary_csv(const std::filesystem::path& path,
                       const std::vector<ConditionSummary>& summary) {
  AtomicFile file(path);
  file.write("condition,measure,mean,sd,n\n");
  for (const ConditionSummary& row : summary)
    file.print("{},{},{:.9g},{:.9g},{}\n", csv_field(row.condition), csv_field(row.measure),
               row.mean, row.sd, row.n);
  file.commit();
}

}  // namespace cohaptic
