#include <pointhaptics/lod/selection.hpp>

#include <pointhaptics/core/error.hpp>

#include <fmt/format.h>

#include <chrono>
#include <cmath>

namespace pointhaptics {

void validate(const LodParams& p) {
  if (!(p.k1 >= 0) || !std::isfinite(p.k1)) throw Error(fmt::format("lod.k1 = {} must be >= 0", p.k1));
  if (!(p.k2 >= p.k1) || !std::isfinite(p.k2)) throw Error(fmt::format("lod.k2 = {} must be >= k1 = {}", p.k2, p.k1));
  double previous_distance = p.k2;
  int previous_k = 0;
  for (std::size_t i = 0; i < p.levels.size(); ++i) {
    const LodLevel& l = p.levels[i];
    if (!(l.distance > previous_distance) || !std::isfinite(l.distance))
      throw Error(fmt::format("lod.levels[{}].distance = {} must exceed {} (k2 or the previous level)", i, l.distance,
                              previous_distance));
    if (l.K < 0 || l.K > 10) throw Error(fmt::format("lod.levels[{}].K = {} must lie in [0, 10]", i, l.K));
    if (l.K < previous_k)
      throw Error(fmt::format("lod.levels[{}].K = {} must not be below the previous level's {}", i, l.K, previous_k));
    previous_distance = l.distance;
    previous_k = l.K;
  }
  if (!(p.reselect > 0) || !std::isfinite(p.reselect))
    throw Error(fmt::format("lod.reselect = {} must be > 0 (units of h)", p.reselect));
  if (!(p.reselect_interval >= 0) || !std::isfinite(p.reselect_interval))
    throw Error(fmt::format("lod.reselect_interval = {} must be >= 0 (s)", p.reselect_interval));
  if (p.min_neighbours < 1) throw Error(fmt::format("lod.min_neighbours = {} must be >= 1", p.min_neighbours));
  if (!(p.max_widening >= 1) || !std::isfinite(p.max_widening))
    throw Error(fmt::format("lod.max_widening = {} must be >= 1", p.max_widening));
}

double dither_threshold(const Vec3& X, double spacing) {
  // the 2x2x2 order: opposite corners first (000, 111), then the remaining opposite pairs (110, 001),
  // (101, 010), (011, 100), so that every prefix is spread as evenly as the cube allows
  static constexpr int base[2][2][2] = {{{0, 3}, {5, 6}}, {{7, 4}, {2, 1}}};  // base[x][y][z]
  int cell[3];
  for (int a = 0; a < 3; ++a) {
    const long long k = std::llround(std::floor(X[a] / spacing + 0.5));
    cell[a] = static_cast<int>(((k % 4) + 4) % 4);
  }
  // the finest level varies slowest in the threshold order (Bayer's recursion): thresholds below any
  // fraction p take every 2x2x2 block's first points before any block's later ones
  const int value = 8 * base[cell[0] & 1][cell[1] & 1][cell[2] & 1] + base[cell[0] >> 1][cell[1] >> 1][cell[2] >> 1];
  return 10.0 * (value + 0.5) / 64.0;
}

Selection select_points(const Model& model, const Vec3& c, const LodParams& params, std::mt19937_64& rng) {
  validate(params);
  if (!c.allFinite()) throw Error("lod: the contact point is not finite");
  const auto start = std::chrono::steady_clock::now();
  const double h = model.h, tr1 = params.k1 * h, tr2 = params.k2 * h;
  std::uniform_real_distribution<double> ran(0.0, 10.0);
  Selection s;
  s.centre = c;
  s.outer_radius = params.levels.empty() ? tr2 : params.levels.back().distance * h;
  s.core_radius = tr2;
  const std::size_t n_bands = 2 + params.levels.size();
  s.band.assign(model.n_points, -1);
  s.band_count.assign(n_bands, 0);
  s.band_selected.assign(n_bands, 0);
  for (index_t i = 0; i < model.n_points; ++i) {
    const double d = (model.X.col(i) - c).norm();
    // one draw per point, whatever its band: the sequence depends on the seed only
    const double draw = ran(rng);
    const double r = params.scheme == LodScheme::RANDOM ? draw : dither_threshold(model.X.col(i), model.spacing);
    int band = -1;
    bool take = false;
    if (d <= tr1) {
      band = 0;
      take = true;
    } else if (d <= tr2) {
      band = 1;
      take = r > 2.0;
    } else {
      for (std::size_t l = 0; l < params.levels.size(); ++l)
        if (d <= params.levels[l].distance * h) {
          band = static_cast<int>(2 + l);
          take = r >= params.levels[l].K;
          break;
        }
    }
    s.band[i] = static_cast<std::int8_t>(band);
    if (band >= 0) ++s.band_count[band];
    if (take && band >= 0) ++s.band_selected[band];
    if (take || model.fixed[i]) s.selected.push_back(i);
  }
  s.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return s;
}

}  // namespace pointhaptics
