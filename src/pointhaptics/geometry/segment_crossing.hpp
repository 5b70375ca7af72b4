#pragma once
/// @file Where a segment crosses a triangle: the visibility test of cutting (Pauly et al. 2005), shared by the
/// cut of the points' pairs (mechanics/cut.hpp) and the split of the object's surface (cut_surface.hpp).
#include <pointhaptics/core/types.hpp>

#include <algorithm>
#include <optional>

namespace pointhaptics {

/// A triangle (a, b, c) made ready for many segment tests: its normal once, and each end's side of its plane
/// once for all the segments it ends (a point's pairs).
struct CrossingTriangle {
  Vec3 a, b, c, normal;
  CrossingTriangle(const Vec3& a_, const Vec3& b_, const Vec3& c_)
      : a(a_), b(b_), c(c_), normal((b_ - a_).cross(c_ - a_)) {}
  /// Sweeps nothing (a blade moved along its own edge here).
  bool degenerate() const { return normal.squaredNorm() == 0; }
  /// Which side of the plane p is on, scaled: a point on the plane counts as on the normal's side (>= 0).
  double side(const Vec3& p) const { return normal.dot(p - a); }
  /// Where p-q crosses the triangle, given side(p) and side(q): the ends on different sides and the crossing
  /// point inside the triangle or on its edges (barycentric coordinates all non-negative, with a relative
  /// tolerance so that a crossing on the edge two triangles share, rounded either way, is in at least one).
  std::optional<Vec3> crossing(const Vec3& p, const Vec3& q, double sp, double sq) const {
    if ((sp >= 0) == (sq >= 0) || degenerate()) return std::nullopt;
    const Vec3 x = p + (sp / (sp - sq)) * (q - p);
    const double slack = -1e-9 * normal.squaredNorm();
    if (normal.dot((b - a).cross(x - a)) >= slack && normal.dot((c - b).cross(x - b)) >= slack &&
        normal.dot((a - c).cross(x - c)) >= slack)
      return x;
    return std::nullopt;
  }
};

/// Where the segment p-q crosses triangle (a, b, c), if it does (CrossingTriangle::crossing()).
inline std::optional<Vec3> segment_crossing(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const CrossingTriangle t(a, b, c);
  return t.crossing(p, q, t.side(p), t.side(q));
}

/// The distance from p to the segment a-b.
inline double distance_to_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double t = ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

}  // namespace pointhaptics
