#pragma once
/// @file Level-of-detail point selection around a contact point (seed §3, design.md "Levels of detail").
#include <pointhaptics/core/model.hpp>

#include <cstdint>
#include <random>
#include <vector>

namespace pointhaptics {

/// A propagation level: the points with P_(i-1) < d <= P_i are selected with probability (10 - K) / 10.
struct LodLevel {
  double distance = 2.5;  ///< P_i, in units of h, increasing with i and beyond k2
  int K = 6;              ///< in [0, 10], non-decreasing with i
};

struct LodParams {
  double k1 = 1.0;               ///< T_r1 = k1 h: every point within is selected
  double k2 = 1.5;               ///< T_r2 = k2 h: points within (T_r1, T_r2] are selected if Ran > 2
  std::vector<LodLevel> levels;  ///< propagation levels beyond T_r2 (none: nothing beyond T_r2)
  std::uint64_t seed = 1;        ///< of the random generator, so that runs are reproducible
};

/// Throws Error naming the parameter if the bands are not well ordered or a K is outside [0, 10].
void validate(const LodParams& params);

/// The band of each point: 0 within T_r1, 1 within T_r2, 1 + i within level i, -1 beyond the last level.
struct Selection {
  std::vector<index_t> selected;          ///< sorted point indices (fixed points always included)
  std::vector<std::int8_t> band;          ///< per point
  std::vector<index_t> band_count;        ///< points per band (0, 1, 1 + i), selected or not
  std::vector<index_t> band_selected;     ///< selected points per band
  double milliseconds = 0;                ///< time the selection took
};

/// Select the points around the contact point c (reference configuration, m) as the seed does: for each
/// point at distance d, draw Ran uniform in [0, 10); d <= T_r1: selected; T_r1 < d <= T_r2: selected if
/// Ran > 2; level i: selected if Ran >= K_i; beyond the last level: not selected; held points always.
/// The generator advances once per point in index order, so a seed gives one selection.
Selection select_points(const Model& model, const Vec3& c, const LodParams& params, std::mt19937_64& rng);

}  // namespace pointhaptics
