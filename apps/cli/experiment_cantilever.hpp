#pragma once
/// @file `pointhaptics experiment cantilever`: seed Fig. 3-4 against CalculiX and beam theory.
#include <string>

namespace pointhaptics::experiments {

struct CantileverOptions {
  std::string out = "cantilever-out";  ///< output folder
  bool quick = false;                  ///< a reduced set (two spacings, two loads, coarse FEM): seconds
  int threads = 0;                     ///< point model threads (0: all); ccx uses the same
  std::string plot_script;             ///< plot_cantilever.py; empty: the built-in search
};

/// Run the study; writes cantilever.csv, point-load.csv, deformed.csv, summary.md and PNG plots into
/// options.out. Returns the process exit code (non-zero when a solve fails or the plots cannot be made).
int run_cantilever_experiment(const CantileverOptions& options);

}  // namespace pointhaptics::experiments
