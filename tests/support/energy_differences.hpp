#pragma once
// The forces a model's strain energy implies, by central differences: what the force tests check against.
#include <pointhaptics/mechanics/energy.hpp>

namespace pointhaptics::test {

/// -dW/du at u by central differences of strain_energy(), one displacement entry at a time (step eps, m).
inline Points forces_by_differences(const Model& model, Points u, double eps) {
  Points f(3, model.n_points);
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    const double keep = u.data()[k];
    u.data()[k] = keep + eps;
    const double plus = strain_energy(model, u).total();
    u.data()[k] = keep - eps;
    const double minus = strain_energy(model, u).total();
    u.data()[k] = keep;
    f.data()[k] = -(plus - minus) / (2 * eps);
  }
  return f;
}

}  // namespace pointhaptics::test
