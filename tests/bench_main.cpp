// cohaptic_bench's main: Google Benchmark's, with every log line on stderr first, so that
// stdout is only the requested table, JSON or CSV (`--benchmark_format=json` parses).
#include <benchmark/benchmark.h>

#include "common/util/log_to_stderr.h"

int main(int argc, char** argv) {
  cohaptic::log_to_stderr();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
