#pragma once
// Small models and random fields shared by the tests.
#include <pointhaptics/geometry/sampling.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>

#include <random>

namespace pointhaptics::test {

/// A box grid of nx x ny x nz points at `spacing`, optionally jittered by `jitter` x spacing
/// (uniform per coordinate), with volumes from the unjittered grid.
inline PointCloud jittered_box(int nx, int ny, int nz, double spacing, double jitter, unsigned seed = 1) {
  PointCloud cloud = sample_box(Vec3::Zero(), spacing * Vec3(nx - 1, ny - 1, nz - 1), spacing);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(-jitter * spacing, jitter * spacing);
  for (Eigen::Index k = 0; k < cloud.X.size(); ++k) cloud.X.data()[k] += uni(rng);
  return cloud;
}

/// A 12 x 4 x 4 cantilever of points at `spacing` (jittered by a tenth of it), E = 1e5 Pa, nu = 0.3, held at x = 0:
/// the reduced model's tests' object.
inline Model jittered_cantilever(double spacing, MaterialModel material = MaterialModel::SVK) {
  MaterialParams m;
  m.model = material;
  m.young = 1e5;
  m.poisson = 0.3;
  m.density = 1000;
  Model model = build_model(jittered_box(12, 4, 4, spacing, 0.1), m, KernelParams{});
  for (index_t i = 0; i < model.n_points; ++i) model.fixed[static_cast<std::size_t>(i)] = model.X(0, i) < 0.5 * spacing;
  return model;
}

/// Gaussian random field with standard deviation `scale` per component.
inline Points random_field(index_t n, double scale, unsigned seed = 2) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, scale);
  Points u(3, n);
  for (Eigen::Index k = 0; k < u.size(); ++k) u.data()[k] = noise(rng);
  return u;
}

/// A random rotation matrix.
inline Mat3 random_rotation(unsigned seed = 3) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise;
  Eigen::Quaterniond q(noise(rng), noise(rng), noise(rng), noise(rng));
  return q.normalized().toRotationMatrix();
}

}  // namespace pointhaptics::test
