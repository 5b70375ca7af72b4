#pragma once
/// @file Resolution where it is needed: a region of a sampled body resampled at a finer spacing (the seed's
/// closing idea of sampling more points for accuracy, here where a tool presses). The mechanics takes the
/// mixed spacings through per-point kernel supports (the max(h_i, h_j) rule of the levels of detail).
#include <pointhaptics/core/point_cloud.hpp>

#include <functional>

namespace pointhaptics {

struct Refinement {
  /// whether a position lies in the region grown by a distance (m)
  std::function<bool(const Vec3&, double)> contains;
  PointCloud fine;  ///< the body sampled at the finer spacing (its points outside the region are not used)
};

/// Replaces `cloud`'s points in the region by `refinement.fine`'s: the fine points in it come, the coarse points
/// in it or closer than 0.75 fine spacings to a fine one go. The volumes of the points whose cells changed (the
/// new ones, and the coarse ones within three coarse spacings of the region) are recomputed as clipped
/// Voronoi cells of the body (`inside`) and rescaled to the volume those points stood for before, so the
/// body's volume is unchanged and the others keep theirs. Every point gets its own kernel support: `support`
/// (the coarse points' h) times its spacing over the coarse one. Throws Error for a finer spacing that is
/// not finer, a region that holds no fine point, or a cloud with per-point data from a file.
void refine_region(PointCloud& cloud, const Refinement& refinement, const std::function<bool(const Vec3&)>& inside,
                   double support);

}  // namespace pointhaptics
