#pragma once
/// @file Plain parameter structs: material, kernel and volume choices (all SI units).
#include <string_view>

namespace pointhaptics {

/// Weighting kernels of the seed paper.
enum class KernelType {
  POLY6,      ///< seed Eq. 3
  SPIKY,      ///< seed Eq. 4
  VISCOSITY,  ///< seed Eq. 5
  QUADRATIC,  ///< seed Eq. 6 (with r^2/h^2)
};

/// How point volumes are obtained.
enum class VolumeMode {
  CELL,    ///< tributary cell volume of the sampling (default; volumes sum to the body's volume)
  KERNEL,  ///< the seed's m_i = total mass / N, rho_i = sum_j m_j w_ij (Eq. 7), v_i = m_i / rho_i (Eq. 8)
};

struct MaterialParams {
  double young = 1e5;              ///< Young's modulus E, Pa
  double poisson = 0.4;            ///< Poisson ratio nu, in (-1, 0.5)
  double density = 1000.0;         ///< rho, kg/m^3
  double volume_stiffness = 0.0;   ///< k_v of the volume term 0.5 k_v v (det F - 1)^2, Pa
  double damping = 0.0;            ///< mass-proportional damping, 1/s
  double hourglass = 0.3;          ///< alpha of the zero-energy-mode penalty (averaged-gradient form, docs/mechanics.md); 0: off
  VolumeMode volume = VolumeMode::CELL;

  /// Lame's first parameter lambda = E nu / ((1 + nu)(1 - 2 nu)), Pa.
  double lambda() const { return young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson)); }
  /// Shear modulus mu = E / (2 (1 + nu)), Pa.
  double mu() const { return young / (2.0 * (1.0 + poisson)); }
  /// P-wave speed sqrt((lambda + 2 mu + k_v) / rho), m/s: sets the explicit stable step.
  double p_wave_speed() const;
};

struct KernelParams {
  KernelType type = KernelType::POLY6;
  double support_factor = 2.0;  ///< h = support_factor * spacing, unless `support` is set
  double support = 0.0;         ///< h in m; 0 means "use support_factor"
};

std::string_view to_string(KernelType type);
std::string_view to_string(VolumeMode mode);

}  // namespace pointhaptics
