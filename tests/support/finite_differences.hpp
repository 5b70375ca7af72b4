#pragma once
// Central finite differences over a 3x3 argument, for the energies' tests: each function is checked against
// the difference quotients of the one before (energy -> stress -> stress derivative).
#include <pointhaptics/core/types.hpp>

#include <random>

namespace pointhaptics::test {

/// dW/dG by central differences (4th order), component by component.
template <class Energy>
Mat3 numeric_gradient(Energy&& W, const Mat3& G, double h = 1e-5) {
  Mat3 D;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      Mat3 e = Mat3::Zero();
      e(a, b) = h;
      D(a, b) = (-W(G + 2 * e) + 8 * W(G + e) - 8 * W(G - e) + W(G - 2 * e)) / (12 * h);
    }
  return D;
}

/// The directional derivative of a matrix function P at G along dG (4th order central differences).
template <class Stress>
Mat3 numeric_directional(Stress&& P, const Mat3& G, const Mat3& dG, double h = 1e-5) {
  return (-P(G + 2 * h * dG) + 8 * P(G + h * dG) - 8 * P(G - h * dG) + P(G - 2 * h * dG)) / (12 * h);
}

/// A random matrix with entries uniform in [-scale, scale].
inline Mat3 random_matrix(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> uniform(-scale, scale);
  Mat3 M;
  for (int k = 0; k < 9; ++k) M(k % 3, k / 3) = uniform(rng);
  return M;
}

/// A random rotation.
inline Mat3 random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  const Vec3 axis = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
  return Eigen::AngleAxisd(std::uniform_real_distribution<double>(0.1, 3.0)(rng), axis).toRotationMatrix();
}

}  // namespace pointhaptics::test
