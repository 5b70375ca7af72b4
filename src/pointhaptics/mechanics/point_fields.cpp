#include <pointhaptics/mechanics/point_fields.hpp>

#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/energies/material.hpp>

#include <oneapi/tbb/parallel_for.h>

#include <cmath>

namespace pointhaptics {

PointFields point_fields(const Model& model, const Points& u) {
  const index_t n = model.n_points;
  PointFields f;
  f.cauchy_stress.resize(9, n);
  f.von_mises.resize(n);
  f.energy_density.resize(n);
  with_material(model, [&](const auto& energy) {
    tbb::parallel_for(tbb::blocked_range<index_t>(0, n, 512), [&](const tbb::blocked_range<index_t>& range) {
      for (index_t i = range.begin(); i != range.end(); ++i) {
        const Mat3 G = displacement_gradient(model, u, i);  // seed Eq. 10
        const Mat3 F = Mat3::Identity() + G;
        const Mat3 P = energy.stress(i, G);
        const double J = F.determinant();
        // sigma = P F^T / J; a point whose neighbourhood inverted has no meaningful Cauchy stress: report the
        // first Piola-Kirchhoff one rather than divide by J <= 0
        const Mat3 sigma = J > 1e-12 ? Mat3(P * F.transpose() / J) : P;
        Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(f.cauchy_stress.col(i).data()) = sigma;
        const Mat3 dev = sigma - sigma.trace() / 3.0 * Mat3::Identity();
        f.von_mises[i] = std::sqrt(1.5 * (dev.array() * dev.array()).sum());
        f.energy_density[i] = energy.energy_density(i, G);
      }
    });
  });
  return f;
}

}  // namespace pointhaptics
