#pragma once
/// @file The levels-of-detail experiments (seed §3): `lod-table` (Table 1), `propagation` (Fig. 8-9) and
/// `lod-error` (error against speed-up, the seed's random selection against the dithered one).
#include <string>

namespace pointhaptics::experiments {

struct LodExperimentOptions {
  std::string out;
  bool quick = false;    ///< small objects only (CI)
  int threads = 0;       ///< 0: all hardware threads
  double seconds = 0.5;  ///< wall time per timed configuration
  // lod-error only
  int points = 0;             ///< object size (0: 10000, --quick 1200)
  std::string load = "pull";  ///< pull: 0.01 N at the pole | indent: the pole pushed 1 mm in (prescribed)
  std::string levels;         ///< one configuration instead of the sweep: "k1,k2[;P:K]..." (units of h)
};

/// Writes lod-table.csv, lod-table.md and lod-table.png; returns the exit code.
int run_lod_table_experiment(const LodExperimentOptions& options);
/// Writes propagation.csv, propagation-runs.csv, summary.md, propagation.png and propagation-3d.png.
int run_propagation_experiment(const LodExperimentOptions& options);
/// Writes lod-error.csv, lod-error.md and lod-error.png.
int run_lod_error_experiment(const LodExperimentOptions& options);

}  // namespace pointhaptics::experiments
