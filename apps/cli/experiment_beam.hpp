#pragma once
/// @file `pointhaptics experiment beam-4x1x1`: the benchmark beam against CalculiX, and its cost per
/// simulated second with the explicit and the implicit solver, and with the reduced model (point_reduced).
#include <string>

namespace pointhaptics::experiments {

struct BeamOptions {
  std::string out = "beam-out";
  std::string scene;      ///< scenes/beam-4x1x1.toml
  double duration = 2.0;  ///< simulated seconds for the dynamic runs
  bool implicit = true;   ///< also time the implicit solver (slow)
  int modes = 20;         ///< the point_reduced row's r (0: none)
};

/// Writes beam.csv and summary.md into options.out; returns the process exit code.
int run_beam_experiment(const BeamOptions& options);

}  // namespace pointhaptics::experiments
