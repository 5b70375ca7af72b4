#pragma once
/// @file Basic numeric types shared by every module.
#include <Eigen/Dense>
#include <cstdint>

// Stress maps are small functions called once per stencil in the force loop; GCC otherwise keeps them out of
// line and the loop loses ~20% returning the 3x3 through memory. (An attribute only: free functions add inline.)
#if defined(__GNUC__)
#define PH_ALWAYS_INLINE __attribute__((always_inline))
#else
#define PH_ALWAYS_INLINE
#endif

namespace pointhaptics {

using index_t = std::int32_t;  ///< point and neighbour-pair indices
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Points = Eigen::Matrix3Xd;  ///< one column per point (3 x n)

}  // namespace pointhaptics
