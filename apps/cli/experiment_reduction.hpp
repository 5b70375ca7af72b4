#pragma once
/// @file `pointhaptics experiment reduction`: the reduced model (issue 49, item 3) against the full point model and
/// CalculiX NLGEOM on two cantilevers, the seed's and one of other proportions, material and load: static tip
/// displacement up to 20% of the length, the response to a suddenly applied load, and the first natural
/// frequency, against the number of modes (CSV, markdown, PNG).
#include <string>
#include <vector>

namespace pointhaptics::experiments {

struct ReductionOptions {
  std::string out = "reduction-out";
  bool quick = false;       ///< the coarser check beam, two loads, three sizes of basis, one CalculiX mesh
  std::vector<int> modes;   ///< the basis sizes r (default 6, 10, 15, 20, 30, 40; --quick: 6, 12, 20)
  int checked_modes = 20;   ///< the r whose errors are checked against the goals (2% and 1%)
  int threads = 0;          ///< 0: all
  std::string plot_script;  ///< plot_reduction.py to use (empty: the source tree's or the installed one)
};

/// Writes reduction.csv, summary.md and reduction.png into options.out; returns 0 when every checked figure is
/// within its goal, 1 otherwise (each miss named on stderr).
int run_reduction_experiment(const ReductionOptions& options);

}  // namespace pointhaptics::experiments
