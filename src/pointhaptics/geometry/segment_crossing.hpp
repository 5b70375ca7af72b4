#pragma once
/// @file Where a segment crosses a triangle: the visibility test of cutting (Pauly et al. 2005), shared by the
/// cut of the points' pairs (mechanics/cut.hpp) and the split of the object's surface (cut_surface.hpp).
#include <pointhaptics/core/types.hpp>

#include <algorithm>
#include <optional>

namespace pointhaptics {

/// Where the segment p-q crosses triangle (a, b, c), if it does: p and q on different sides of its plane (a
/// point on the plane is on the normal's side) and the crossing point inside the triangle or on its edges.
inline std::optional<Vec3> segment_crossing(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 normal = (b - a).cross(c - a);
  if (normal.squaredNorm() == 0) return std::nullopt;  // a blade moved along its own edge here: it sweeps nothing
  const double sp = normal.dot(p - a), sq = normal.dot(q - a);
  if ((sp >= 0) == (sq >= 0)) return std::nullopt;
  const Vec3 crossing = p + (sp / (sp - sq)) * (q - p);
  // inside: on the inner side of each edge (barycentric coordinates all non-negative), with a relative
  // tolerance so that a crossing on the edge two triangles share, rounded either way, is in at least one
  const double slack = -1e-9 * normal.squaredNorm();
  if (normal.dot((b - a).cross(crossing - a)) >= slack && normal.dot((c - b).cross(crossing - b)) >= slack &&
      normal.dot((a - c).cross(crossing - c)) >= slack)
    return crossing;
  return std::nullopt;
}

/// The distance from p to the segment a-b.
inline double distance_to_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double t = ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

}  // namespace pointhaptics
