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
}

Selection select_points(const Model& model, const Vec3& c, const LodParams& params, std::mt19937_64& rng) {
  validate(params);
  if (!c.allFinite()) throw Error("lod: the contact point is not finite");
  const auto start = std::chrono::steady_clock::now();
  const double h = model.h, tr1 = params.k1 * h, tr2 = params.k2 * h;
  std::uniform_real_distribution<double> ran(0.0, 10.0);
  Selection s;
  const std::size_t n_bands = 2 + params.levels.size();
  s.band.assign(model.n_points, -1);
  s.band_count.assign(n_bands, 0);
  s.band_selected.assign(n_bands, 0);
  for (index_t i = 0; i < model.n_points; ++i) {
    const double d = (model.X.col(i) - c).norm();
    const double r = ran(rng);  // one draw per point, whatever its band: the sequence depends on the seed only
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
