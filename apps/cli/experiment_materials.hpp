#pragma once
/// @file `pointhaptics experiment materials`: each hyperelastic model against CalculiX's own (issue 17).
#include <string>
#include <vector>

namespace pointhaptics::experiments {

struct MaterialsOptions {
  std::string out = "materials-out";  ///< output folder
  bool quick = false;                 ///< coarse CalculiX meshes only (a minute)
  int threads = 0;                    ///< point model and ccx threads (0: all)
  std::string plot_script;            ///< plot_materials.py; empty: the built-in search
  std::vector<std::string> models;    ///< of svk, neo_hookean, mooney_rivlin; empty: all three
  /// CalculiX's punch meshes, elements across the block (even: it solves a quarter with half as many a side);
  /// the point model is compared with the last. Empty: 10, 20, 40 (quick: 10)
  std::vector<int> punch_meshes;
};

/// For svk (*ELASTIC with NLGEOM), neo_hookean (NEO HOOKE) and mooney_rivlin (MOONEY-RIVLIN): the seed's
/// cantilever under 0.3 N at its tip and under gravity, and a flat punch's force against depth up to 5 mm;
/// writes materials.csv, punch.csv, summary.md and PNG plots into options.out. Returns the exit code.
int run_materials_experiment(const MaterialsOptions& options);

}  // namespace pointhaptics::experiments
