#pragma once
/// @file `pointhaptics experiment cut` (issue 18): a device's blade cuts the seed's cantilever through near its
/// root, then a scripted blade cuts a slit into a block that opens under load.
#include <string>

namespace pointhaptics::experiments {

struct CutOptions {
  std::string out = "cut-out";
  int threads = 1;
};

/// Writes cut.json and summary.md into options.out; returns the exit code.
int run_cut_experiment(const CutOptions& options);

}  // namespace pointhaptics::experiments
