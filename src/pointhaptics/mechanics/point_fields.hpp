#pragma once
/// @file Per-point fields for output: stress and strain-energy density at every point.
#include <pointhaptics/core/model.hpp>

namespace pointhaptics {

struct PointFields {
  Eigen::Matrix<double, 9, Eigen::Dynamic> cauchy_stress;  ///< sigma = F S F^T / J, Pa, row-major 3x3  (9 x n)
  Eigen::VectorXd von_mises;                               ///< of sigma, Pa  (n)
  Eigen::VectorXd energy_density;                          ///< elastic + volume energy per reference volume, J/m^3  (n)
};

/// The fields of the displacement u (3 x n) from each point's MLS gradient (seed Eq. 10), Green strain
/// (Eq. 2) and St. Venant-Kirchhoff stress; the zero-energy-mode penalty is numerical and left out.
PointFields point_fields(const Model& model, const Points& u);

}  // namespace pointhaptics
