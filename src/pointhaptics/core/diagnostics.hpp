#pragma once
/// @file Counters that the model build and the solvers fill, reported in results.
#include <cstdint>

namespace pointhaptics {

struct ModelDiagnostics {
  std::int64_t regularised_neighbourhoods = 0;  ///< M_i ill-conditioned (coplanar or too few neighbours): regularised
  std::int64_t isolated_points = 0;             ///< points with no neighbour inside the support
  double min_neighbours = 0;                    ///< fewest neighbours of any point
  double mean_neighbours = 0;                   ///< average neighbours per point
  double worst_condition = 0;                   ///< largest cond(M_i) before regularisation
  std::int64_t severed_pairs = 0;               ///< neighbour pairs cut so far (mechanics/cut.hpp)
};

}  // namespace pointhaptics
