#pragma once
/// @file A sampled body: positions, the volume each point stands for, and flags.
#include <pointhaptics/core/types.hpp>

#include <vector>

namespace pointhaptics {

struct PointCloud {
  Points X;                            ///< positions, m  (3 x n)
  Eigen::VectorXd volume;              ///< volume each point represents, m^3  (n); sums to the body's volume
  std::vector<unsigned char> surface;  ///< 1 where the point lies on the body's surface  (n)
  double spacing = 0;                  ///< nominal sample spacing, m
  Eigen::VectorXd support;             ///< optional per-point kernel support h_i, m (empty: the kernel's one h)
  std::vector<unsigned char> held;     ///< optional, from a file: 1 where the point is held  (n, or empty)
  Eigen::VectorXd intensity;           ///< optional, from a volume image: the nearest voxel's intensity  (n, or empty)
  /// optional: E_i / E of each point (a stiffness map over a volume image's intensity); empty: 1 everywhere
  Eigen::VectorXd stiffness_scale;

  index_t size() const { return static_cast<index_t>(X.cols()); }
};

}  // namespace pointhaptics
