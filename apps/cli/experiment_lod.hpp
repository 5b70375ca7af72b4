#pragma once
/// @file The levels-of-detail experiments (seed §3): `lod-table` (Table 1), `propagation` (Fig. 8-9) and
/// `lod-error` (error against speed-up, the seed's random selection against the dithered one).
#include <string>

namespace pointhaptics::experiments {

struct LodExperimentOptions {
  std::string out;
  bool quick = false;   ///< small objects only (CI)
  int threads = 0;      ///< 0: all hardware threads
  double seconds = 0.5; ///< wall time per timed configuration
};

/// Writes lod-table.csv, lod-table.md and lod-table.png; returns the exit code.
int run_lod_table_experiment(const LodExperimentOptions& options);
/// Writes propagation.csv, propagation-runs.csv, summary.md, propagation.png and propagation-3d.png.
int run_propagation_experiment(const LodExperimentOptions& options);
/// Writes lod-error.csv, lod-error.md and lod-error.png.
int run_lod_error_experiment(const LodExperimentOptions& options);

}  // namespace pointhaptics::experiments
