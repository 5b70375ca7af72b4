// The performance suite as a stand-alone program: pointhaptics_benchmarks [--json FILE] [--filter REGEX]
#include "bench_suite.hpp"

#include <cstring>
#include <string>

int main(int argc, char** argv) {
  pointhaptics::bench::BenchOptions options;
  for (int k = 1; k + 1 < argc; k += 2) {
    if (!std::strcmp(argv[k], "--json")) options.json_path = argv[k + 1];
    else if (!std::strcmp(argv[k], "--filter")) options.filter = argv[k + 1];
    else if (!std::strcmp(argv[k], "--min-time")) options.min_time = std::stod(argv[k + 1]);
  }
  return pointhaptics::bench::run_bench_suite(options);
}
