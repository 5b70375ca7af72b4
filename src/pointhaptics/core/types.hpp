#pragma once
/// @file Basic numeric types shared by every module.
#include <Eigen/Dense>
#include <cstdint>

namespace pointhaptics {

using index_t = std::int32_t;  ///< point and neighbour-pair indices
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Points = Eigen::Matrix3Xd;  ///< one column per point (3 x n)

}  // namespace pointhaptics
