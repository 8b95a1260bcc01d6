// cohaptic_bench's stdout is what it was asked for: with --benchmark_format=json it parses
// as JSON, although building the benchmarks' models logs (to stderr), and it holds naive and
// incremental M~ updates side by side, paired by name. Run at |B| = 0, the tiny size.
// Built only with the benchmarks (COHAPTIC_BUILD_BENCHMARKS).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <set>
#include <string>

#include "support/run_program.h"

namespace cohaptic {
namespace {

TEST(BenchOutput, JsonOnStdoutParsesAndPairsNaiveWithIncremental) {
  const testing::ProgramRun run =
      testing::run_program(COHAPTIC_BENCH_EXE,
                           "--benchmark_format=json --benchmark_filter='(naive|incremental)/0$' "
                           "--benchmark_min_time=0.01");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  nlohmann::json json;
  ASSERT_NO_THROW(json = nlohmann::json::parse(run.out)) << "stdout is not JSON:\n"
                                                         << run.out.substr(0, 2000);
  ASSERT_TRUE(json.contains("benchmarks")) << run.out.substr(0, 2000);
  std::set<std::string> names;
  for (const nlohmann::json& benchmark : json["benchmarks"]) {
    names.insert(benchmark.at("name").get<std::string>());
    EXPECT_GT(benchmark.at("real_time").get<double>(), 0) << benchmark.dump();
  }
  for (const char* name : {"BM_MtildeUpdate/naive/0", "BM_MtildeUpdate/incremental/0",
                           "BM_TriangleChange/naive/0", "BM_TriangleChange/incremental/0"})
    EXPECT_TRUE(names.count(name)) << name << " missing from the JSON";
  for (const std::string& name : names)
    EXPECT_TRUE(name.find("naive") != std::string::npos ||
                name.find("incremental") != std::string::npos)
        << name << " passed a filter it should not have";
}

}  // namespace
}  // namespace cohaptic
