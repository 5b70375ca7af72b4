#pragma once
/// @file A rigid shape's pose and the distance from a point to it, for tools and obstacles alike: a sphere (the
/// probe), a capsule (a cylinder with rounded ends, the seed's cylindrical probe of Fig. 2), a box, or a plane
/// (a half-space: a table). A sphere and a capsule are the points within `radius` of a core (the centre, the axis
/// segment); a box is the points within `radius` of its core box (its edges rounded by `radius`); a plane is the
/// half-space below its local xy plane (its normal, local +z, points out of it).
#include <pointhaptics/core/types.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pointhaptics {

enum class ToolKind { SPHERE, CAPSULE, BOX, PLANE };

struct ToolShape {
  ToolKind kind = ToolKind::SPHERE;
  double radius = 0.005;          ///< m (a box: the rounding of its edges; a plane: the scale of its defaults only)
  double length = 0;              ///< capsule: its axis segment (the cylinder's length), m, along the tool's local z
  Vec3 half_core = Vec3::Zero();  ///< box: its core's half sizes along the local axes, m (the box is radius wider)
};

/// How far from the tool's position a point can touch it, m (a plane: everywhere).
inline double tool_reach(const ToolShape& shape) {
  switch (shape.kind) {
    case ToolKind::PLANE: return std::numeric_limits<double>::infinity();
    case ToolKind::BOX: return shape.radius + shape.half_core.norm();
    default: return shape.radius + 0.5 * shape.length;
  }
}

struct ToolPose {
  Vec3 position = Vec3::Zero();                                     ///< the core's midpoint, m
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< tool to scene axes
};

/// Where a point is seen from the tool.
struct ToolDistance {
  Vec3 core = Vec3::Zero();     ///< the nearest point of the tool's core (a plane: the point's foot on it)
  Vec3 normal = Vec3::UnitZ();  ///< unit, from `core` toward the point: the tool's outward normal there
  double penetration = 0;       ///< of the point into the tool, m (> 0 inside): radius - |point - core|
  /// d normal / d point = curvature (I - n n^T) J: curvature = 1 / |point - core| on a rounded part (0 on a
  /// flat one: a plane, a box's face); J = I when the nearest core point is a centre or a corner, the
  /// projection off `axis` when it slides along a segment (a capsule's axis, a box's edge: moving the point
  /// along it moves the core point with it). `axis` is zero for J = I.
  double curvature = 0;
  Vec3 axis = Vec3::Zero();
};

namespace detail {
// a rounded core: the point seen from its nearest core point (local +z of the pose when on the core itself)
inline void round_core(const ToolShape& shape, const ToolPose& pose, const Vec3& point, ToolDistance& d) {
  const Vec3 r = point - d.core;
  const double from_core = r.norm();
  const bool off_core = from_core > 1e-12 * shape.radius;
  d.normal = off_core ? Vec3(r / from_core) : Vec3(pose.orientation * Vec3::UnitZ());
  d.penetration = shape.radius - from_core;
  d.curvature = off_core ? 1.0 / from_core : 0.0;
}
}  // namespace detail

/// The distance from `point` to the tool.
inline ToolDistance tool_distance(const ToolShape& shape, const ToolPose& pose, const Vec3& point) {
  ToolDistance d;
  d.core = pose.position;
  switch (shape.kind) {
    case ToolKind::PLANE: {
      d.normal = pose.orientation * Vec3::UnitZ();
      const double above = d.normal.dot(point - pose.position);
      d.core = point - above * d.normal;
      d.penetration = -above;
      return d;
    }
    case ToolKind::BOX: {
      const Vec3 local = pose.orientation.conjugate() * (point - pose.position);
      const Vec3 clamped = local.cwiseMax(-shape.half_core).cwiseMin(shape.half_core);
      int inside_axes = 0, free_axis = -1;
      for (int a = 0; a < 3; ++a)
        if (clamped[a] == local[a]) ++inside_axes, free_axis = a;
      if (inside_axes == 3) {
        // inside the core: out through the nearest face (flat there)
        const Vec3 room = shape.half_core - local.cwiseAbs();
        int a = 0;
        room.minCoeff(&a);
        Vec3 n_local = Vec3::Zero();
        n_local[a] = local[a] < 0 ? -1.0 : 1.0;
        d.normal = pose.orientation * n_local;
        Vec3 on_face = local;
        on_face[a] = n_local[a] * shape.half_core[a];
        d.core = pose.position + pose.orientation * on_face;
        d.penetration = shape.radius + room[a];
        return d;
      }
      d.core = pose.position + pose.orientation * clamped;
      detail::round_core(shape, pose, point, d);
      if (inside_axes == 2) {
        // a face: flat
        d.curvature = 0;
      } else if (inside_axes == 1) {
        // an edge: the core point slides along it
        Vec3 axis_local = Vec3::Zero();
        axis_local[free_axis] = 1.0;
        d.axis = pose.orientation * axis_local;
      }
      return d;
    }
    case ToolKind::CAPSULE:
      if (shape.length > 0) {
        const Vec3 axis = pose.orientation * Vec3::UnitZ();
        const double half = 0.5 * shape.length;
        const double along = (point - pose.position).dot(axis);
        d.core = pose.position + std::clamp(along, -half, half) * axis;
        if (std::abs(along) < half) d.axis = axis;
      }
      break;
    case ToolKind::SPHERE: break;
  }
  detail::round_core(shape, pose, point, d);
  return d;
}

}  // namespace pointhaptics
