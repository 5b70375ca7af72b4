#pragma once
/// @file The viewer's orbit camera: a target point, a distance and two angles (y is up), with the
/// matrices OpenGL wants and the mappings between scene points and window pixels.
#include <pointhaptics/core/types.hpp>

#include <Eigen/Core>

namespace pointhaptics::viewer {

using Mat4 = Eigen::Matrix4d;

/// A rectangle of the window in pixels, origin at the top left (as the mouse and images count).
struct Viewport {
  double x = 0, y = 0, width = 1, height = 1;
  bool contains(double px, double py) const { return px >= x && py >= y && px < x + width && py < y + height; }
};

/// A ray from the eye through a pixel.
struct Ray {
  Vec3 origin, direction;  ///< direction has unit length
};

class OrbitCamera {
 public:
  Vec3 target = Vec3::Zero();
  double distance = 1.0;  ///< eye to target, m
  double yaw = 0.35;      ///< about y, rad (0: looking along -z)
  double pitch = 0.55;    ///< above the horizontal, rad
  double fov_y = 0.6;     ///< vertical field of view, rad

  /// Look at the box [lo, hi] from the current angles, from far enough to see all of it.
  void frame(const Vec3& lo, const Vec3& hi);
  Vec3 eye() const;
  Vec3 forward() const;  ///< unit, eye toward target
  Vec3 right() const;    ///< unit, screen right
  Vec3 up() const;       ///< unit, screen up

  /// Drag by (dx, dy) pixels: orbit (a window height turns by about pi), pan (the target follows the
  /// cursor at its depth), zoom by a factor (> 1 moves away).
  void orbit(double dx, double dy, const Viewport& vp);
  void pan(double dx, double dy, const Viewport& vp);
  void zoom(double factor);

  Mat4 view() const;
  Mat4 projection(double aspect) const;  ///< near and far from the distance
  double near_plane() const { return distance * 0.01; }
  double far_plane() const { return distance * 100.0; }

  /// The window pixel (x right, y down) of a scene point, and its depth along the view (m); NaN pixel
  /// behind the eye.
  Eigen::Vector2d project(const Vec3& p, const Viewport& vp) const;
  Ray ray(double px, double py, const Viewport& vp) const;
  /// Pixels per metre at a depth (along the view) of `depth` m.
  double pixels_per_metre(double depth, const Viewport& vp) const;
};

/// Where the ray meets the plane through `point` facing the camera (NaN if it never does).
Vec3 on_view_plane(const OrbitCamera& camera, const Ray& ray, const Vec3& point);

/// How the mouse moves the probe's hand target: nothing until the cursor first moves, then the target
/// follows the cursor's motion in the plane facing the camera through it, anchored where it was (issue 21:
/// following the cursor's absolute position put the probe into the object at start, wherever the pointer
/// happened to be). reset() re-anchors (after the camera or the target's depth changed).
class CursorAnchor {
 public:
  /// The new target for the cursor at pixel (cx, cy) of `vp`.
  Vec3 follow(const OrbitCamera& camera, const Viewport& vp, double cx, double cy, const Vec3& target);
  void reset() { offset_ = Vec3::Constant(NAN); }

 private:
  Vec3 offset_ = Vec3::Constant(NAN);  ///< target minus the cursor's point on the plane
  double start_x_ = NAN, start_y_ = NAN;
  bool moved_ = false;
};

}  // namespace pointhaptics::viewer
