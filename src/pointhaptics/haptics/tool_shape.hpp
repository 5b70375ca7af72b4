#pragma once
/// @file A tool's shape and pose, and the distance from a point to it: a sphere (the probe), or a capsule
/// (a cylinder with rounded ends, the seed's cylindrical probe of Fig. 2). Both are the set of points within
/// `radius` of a core: the sphere's centre, or the capsule's axis segment.
#include <pointhaptics/core/types.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace pointhaptics {

enum class ToolKind { SPHERE, CAPSULE };

struct ToolShape {
  ToolKind kind = ToolKind::SPHERE;
  double radius = 0.005;  ///< m
  double length = 0;      ///< capsule: its axis segment (the cylinder's length), m, along the tool's local z
};

/// How far from the tool's position a point can touch it, m: its radius plus half its axis.
inline double tool_reach(const ToolShape& shape) { return shape.radius + 0.5 * shape.length; }

struct ToolPose {
  Vec3 position = Vec3::Zero();                                     ///< the core's midpoint, m
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< tool to scene axes
};

/// Where a point is seen from the tool.
struct ToolDistance {
  Vec3 core = Vec3::Zero();     ///< the nearest point of the tool's core
  Vec3 normal = Vec3::UnitZ();  ///< unit, from `core` toward the point: the tool's outward normal there
  double from_core = 0;         ///< |point - core|, m
  /// d normal / d point = (I - n n^T) J / from_core: J = I when the nearest core point is the centre or a
  /// segment's end, the projection off the axis when it is inside the segment (moving the point along the
  /// axis moves the core point with it). `axis` is that axis (zero for J = I).
  Vec3 axis = Vec3::Zero();
  /// Penetration of the point into the tool, m (> 0 inside): radius - from_core.
  double penetration(const ToolShape& shape) const { return shape.radius - from_core; }
};

/// The distance from `point` to the tool. A point on the core itself (no direction) gets the tool's local
/// +z as its normal.
inline ToolDistance tool_distance(const ToolShape& shape, const ToolPose& pose, const Vec3& point) {
  ToolDistance d;
  d.core = pose.position;
  if (shape.kind == ToolKind::CAPSULE && shape.length > 0) {
    const Vec3 axis = pose.orientation * Vec3::UnitZ();
    const double half = 0.5 * shape.length;
    const double along = (point - pose.position).dot(axis);
    d.core = pose.position + std::clamp(along, -half, half) * axis;
    if (std::abs(along) < half) d.axis = axis;
  }
  const Vec3 r = point - d.core;
  d.from_core = r.norm();
  d.normal = d.from_core > 1e-12 * shape.radius ? Vec3(r / d.from_core) : Vec3(pose.orientation * Vec3::UnitZ());
  return d;
}

}  // namespace pointhaptics
