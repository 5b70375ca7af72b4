#pragma once
/// @file Level-of-detail point selection around a contact point (seed §3, design.md "Levels of detail").
#include <pointhaptics/core/model.hpp>

#include <cstdint>
#include <random>
#include <vector>

namespace pointhaptics {

/// Throws Error naming the parameter if the bands are not well ordered or a K is outside [0, 10].
void validate(const LodParams& params);

/// The ordered-dither draw in [0, 10) of a point at X on a lattice of `spacing` (LodScheme::DITHER): a
/// 4x4x4 Bayer-style matrix, so that in every 4x4x4 block the points with threshold >= K are the
/// (10 - K) / 10 fraction spread farthest apart.
double dither_threshold(const Vec3& X, double spacing);

/// The band of each point: 0 within T_r1, 1 within T_r2, 1 + i within level i, -1 beyond the last level.
struct Selection {
  std::vector<index_t> selected;       ///< sorted point indices (fixed points always included)
  std::vector<std::int8_t> band;       ///< per point
  std::vector<index_t> band_count;     ///< points per band (0, 1, 1 + i), selected or not
  std::vector<index_t> band_selected;  ///< selected points per band
  double milliseconds = 0;             ///< time the selection took
  Vec3 centre = Vec3::Zero();          ///< the contact point it was made around, m
  double outer_radius = 0;             ///< of the last band, m (no point beyond it is in a band)
  double core_radius = 0;              ///< T_r2, m: every point within it is simulated or absorbed by one that is
};

/// Select the points around the contact point c (reference configuration, m) as the seed does: for each
/// point at distance d, draw Ran uniform in [0, 10); d <= T_r1: selected; T_r1 < d <= T_r2: selected if
/// Ran > 2; level i: selected if Ran >= K_i; beyond the last level: not selected; held points always.
/// The generator advances once per point in index order, so a seed gives one selection.
Selection select_points(const Model& model, const Vec3& c, const LodParams& params, std::mt19937_64& rng);

}  // namespace pointhaptics
