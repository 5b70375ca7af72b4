#pragma once
/// @file The performance suite (Google Benchmark), shared by `pointhaptics bench` and pointhaptics_benchmarks.
#include <string>
#include <vector>

namespace pointhaptics::bench {

struct BenchOptions {
  std::string json_path;                        ///< write design.md's bench JSON here ("" = don't)
  std::string filter = ".";                     ///< benchmark name regex
  double min_time = 0.2;                        ///< seconds per benchmark
  std::vector<int> sizes{1000, 10000, 100000};  ///< approximate point counts
  std::vector<int> threads{1, 2};
  int repetitions = 1;  ///< > 1: each benchmark this many times, interleaved at random, medians reported
};

/// Register the suite, run it, print a table on stdout and write the JSON. Returns a process exit code.
int run_bench_suite(const BenchOptions& options);

}  // namespace pointhaptics::bench
