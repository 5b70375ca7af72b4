#pragma once
/// @file The seed's weighting kernels (Eq. 3-6), each normalised to unit integral over the 3D ball of radius h.
#include <pointhaptics/core/parameters.hpp>

namespace pointhaptics {

/// w(r, h): positive for 0 < r < h, non-increasing in r, zero for r >= h.
/// \note Eq. 5 (viscosity) is infinite at r = 0; it is never evaluated there (a point is not its own neighbour).
/// \note Eq. 6 is printed with r^2/h; its branches meet at r = h/2 only with r^2/h^2, which is used here,
///       scaled by 4 / (pi h^3) so that it integrates to one.
double kernel_value(KernelType type, double r, double h);

/// dw/dr.
double kernel_derivative(KernelType type, double r, double h);

}  // namespace pointhaptics
