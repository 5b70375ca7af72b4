#include "camera.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pointhaptics::viewer {

void OrbitCamera::frame(const Vec3& lo, const Vec3& hi) {
  target = 0.5 * (lo + hi);
  const double radius = std::max(0.5 * (hi - lo).norm(), 1e-6);
  distance = 1.05 * radius / std::sin(0.5 * fov_y);
}

Vec3 OrbitCamera::forward() const {
  return -Vec3(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
}
Vec3 OrbitCamera::eye() const { return target - distance * forward(); }
Vec3 OrbitCamera::right() const { return forward().cross(Vec3::UnitY()).normalized(); }
Vec3 OrbitCamera::up() const { return right().cross(forward()); }

void OrbitCamera::orbit(double dx, double dy, const Viewport& vp) {
  const double per_pixel = std::numbers::pi / std::max(vp.height, 1.0);
  yaw -= dx * per_pixel;
  // stop short of the poles, where "up" is undefined
  pitch = std::clamp(pitch + dy * per_pixel, -1.5, 1.5);
}

void OrbitCamera::pan(double dx, double dy, const Viewport& vp) {
  const double m = 1.0 / pixels_per_metre(distance, vp);
  target += (-dx * right() + dy * up()) * m;
}

void OrbitCamera::zoom(double factor) { distance = std::clamp(distance * factor, 1e-5, 1e5); }

Mat4 OrbitCamera::view() const {
  const Vec3 f = forward(), r = right(), u = up(), e = eye();
  Mat4 v = Mat4::Identity();
  v.block<1, 3>(0, 0) = r.transpose();
  v.block<1, 3>(1, 0) = u.transpose();
  v.block<1, 3>(2, 0) = -f.transpose();
  v(0, 3) = -r.dot(e);
  v(1, 3) = -u.dot(e);
  v(2, 3) = f.dot(e);
  return v;
}

Mat4 OrbitCamera::projection(double aspect) const {
  const double n = near_plane(), f = far_plane(), t = 1.0 / std::tan(0.5 * fov_y);
  Mat4 p = Mat4::Zero();
  p(0, 0) = t / aspect;
  p(1, 1) = t;
  p(2, 2) = -(f + n) / (f - n);
  p(2, 3) = -2.0 * f * n / (f - n);
  p(3, 2) = -1.0;
  return p;
}

Eigen::Vector2d OrbitCamera::project(const Vec3& p, const Viewport& vp) const {
  const Eigen::Vector4d c = projection(vp.width / vp.height) * view() * p.homogeneous();
  if (!(c.w() > 0)) return Eigen::Vector2d::Constant(NAN);
  const double x = c.x() / c.w(), y = c.y() / c.w();
  return {vp.x + 0.5 * (x + 1.0) * vp.width, vp.y + 0.5 * (1.0 - y) * vp.height};
}

Ray OrbitCamera::ray(double px, double py, const Viewport& vp) const {
  const double t = std::tan(0.5 * fov_y);
  const double x = (2.0 * (px - vp.x) / vp.width - 1.0) * t * vp.width / vp.height;
  const double y = (1.0 - 2.0 * (py - vp.y) / vp.height) * t;
  return {eye(), (forward() + x * right() + y * up()).normalized()};
}

double OrbitCamera::pixels_per_metre(double depth, const Viewport& vp) const {
  return 0.5 * vp.height / (std::tan(0.5 * fov_y) * std::max(depth, 1e-12));
}

Vec3 on_view_plane(const OrbitCamera& camera, const Ray& ray, const Vec3& point) {
  const Vec3 n = camera.forward();
  const double along = ray.direction.dot(n);
  if (!(std::abs(along) > 1e-12)) return Vec3::Constant(NAN);
  const double s = (point - ray.origin).dot(n) / along;
  if (!(s > 0)) return Vec3::Constant(NAN);
  return ray.origin + s * ray.direction;
}

Vec3 CursorAnchor::follow(const OrbitCamera& camera, const Viewport& vp, double cx, double cy, const Vec3& target) {
  if (!target.allFinite()) return target;
  if (!moved_) {
    // the first cursor position seen is where the pointer happened to be: wait for it to move
    if (std::isnan(start_x_)) {
      start_x_ = cx;
      start_y_ = cy;
    }
    if (cx == start_x_ && cy == start_y_) return target;
    moved_ = true;
  }
  const Vec3 q = on_view_plane(camera, camera.ray(cx, cy, vp), target);
  if (!q.allFinite()) return target;
  if (!offset_.allFinite()) offset_ = target - q;  // anchored: no jump
  return q + offset_;
}

}  // namespace pointhaptics::viewer
