#include <pointhaptics/mechanics/kernels.hpp>

#include <cmath>
#include <numbers>

namespace pointhaptics {

namespace {
constexpr double pi = std::numbers::pi;
}

double kernel_value(KernelType type, double r, double h) {
  if (r >= h) return 0.0;
  const double q = r / h;
  switch (type) {
    case KernelType::POLY6: {  // seed Eq. 3
      const double a = h * h - r * r;
      return 315.0 / (64.0 * pi * std::pow(h, 9)) * a * a * a;
    }
    case KernelType::SPIKY: {  // seed Eq. 4
      const double a = h - r;
      return 15.0 / (pi * std::pow(h, 6)) * a * a * a;
    }
    case KernelType::VISCOSITY:  // seed Eq. 5
      return 15.0 / (2.0 * pi * h * h * h) * (-0.5 * q * q * q + q * q + 0.5 / q - 1.0);
    case KernelType::QUADRATIC: {  // seed Eq. 6 with r^2/h^2, normalised
      const double c = 4.0 / (pi * h * h * h);
      return q < 0.5 ? c * (1.0 - 2.0 * q * q) : c * 2.0 * (1.0 - q) * (1.0 - q);
    }
  }
  return 0.0;
}

double kernel_derivative(KernelType type, double r, double h) {
  if (r >= h) return 0.0;
  const double q = r / h;
  switch (type) {
    case KernelType::POLY6: {
      const double a = h * h - r * r;
      return 315.0 / (64.0 * pi * std::pow(h, 9)) * 3.0 * a * a * (-2.0 * r);
    }
    case KernelType::SPIKY: {
      const double a = h - r;
      return -15.0 / (pi * std::pow(h, 6)) * 3.0 * a * a;
    }
    case KernelType::VISCOSITY: return 15.0 / (2.0 * pi * h * h * h) * (-1.5 * q * q + 2.0 * q - 0.5 / (q * q)) / h;
    case KernelType::QUADRATIC: {
      const double c = 4.0 / (pi * h * h * h);
      return q < 0.5 ? c * (-4.0 * q) / h : c * (-4.0) * (1.0 - q) / h;
    }
  }
  return 0.0;
}

}  // namespace pointhaptics
