// Tests for mechanics/forces and mechanics/energy: exact gradient, invariance, balance, patch test,
// zero-energy modes; every energy term on and off, several kernels and volume modes, every material model.
#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/energies/svk.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/forces.hpp>

#include "support/energy_differences.hpp"
#include "support/test_models.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

struct Config {
  const char* name;
  double volume_stiffness;  // Pa
  double hourglass;
  KernelType kernel = KernelType::POLY6;
  VolumeMode volume = VolumeMode::CELL;
  double support_factor = 2.0;
  MaterialModel model = MaterialModel::SVK;
};

std::ostream& operator<<(std::ostream& os, const Config& c) { return os << c.name; }

const double spacing = 0.01;

Model make_model(const Config& c, double jitter = 0.2) {
  MaterialParams m;
  m.model = c.model;
  m.young = 1e5;
  m.poisson = 0.4;
  m.volume_stiffness = c.volume_stiffness;
  m.hourglass = c.hourglass;
  m.volume = c.volume;
  KernelParams k;
  k.type = c.kernel;
  k.support_factor = c.support_factor;
  return build_model(test::jittered_box(5, 4, 4, spacing, jitter), m, k);
}

Points forces(const Model& model, const Points& u, int threads = 1) {
  Workspace ws(model, threads);
  compute_internal_forces(model, u, ws);
  return ws.f_int;
}

class ForcesTest : public ::testing::TestWithParam<Config> {};

TEST_P(ForcesTest, EqualMinusCentralDifferencesOfTheEnergy) {
  const Model model = make_model(GetParam());
  for (double scale : {0.02, 0.2}) {  // small and large deformation (strain up to ~50%)
    const Points u = test::random_field(model.n_points, scale * spacing, 17);
    const Points f = forces(model, u);
    const Points f_fd = test::forces_by_differences(model, u, 1e-5 * scale * spacing);
    const double error = (f - f_fd).norm() / f.norm();
    EXPECT_LT(error, 1e-6) << "displacement scale " << scale << " x spacing";
    EXPECT_GT(f.norm(), 0);
  }
}

TEST_P(ForcesTest, RigidMotionsGiveZeroStrainEnergyAndForce) {
  const Model model = make_model(GetParam());
  const Mat3 R = test::random_rotation(9);
  const Vec3 t(0.013, -0.02, 0.007), c = model.X.rowwise().mean();
  Points translation(3, model.n_points), rotation(3, model.n_points);
  for (index_t i = 0; i < model.n_points; ++i) {
    translation.col(i) = t;
    rotation.col(i) = (R - Mat3::Identity()) * (model.X.col(i) - c) + t;
  }
  // force scale: what a 1% strain produces
  const double reference = forces(model, test::random_field(model.n_points, 0.01 * spacing, 4)).norm();
  for (const Points* u : {&translation, &rotation}) {
    for (index_t i = 0; i < model.n_points; ++i)
      EXPECT_LT(green_strain(displacement_gradient(model, *u, i)).norm(), 1e-12);
    EXPECT_LT(std::abs(strain_energy(model, *u).total()), 1e-16 * model.material.young * model.volume.sum());
    EXPECT_LT(forces(model, *u).norm(), 1e-9 * reference);
  }
}

TEST_P(ForcesTest, InternalForcesAndTorquesSumToZero) {
  const Model model = make_model(GetParam());
  const Points u = test::random_field(model.n_points, 0.1 * spacing, 21);
  const Points f = forces(model, u);
  const Points x = model.X + u;
  Vec3 sum = Vec3::Zero(), torque = Vec3::Zero();
  double scale = 0;
  for (index_t i = 0; i < model.n_points; ++i) {
    sum += f.col(i);
    torque += x.col(i).cross(f.col(i));
    scale += f.col(i).norm();
  }
  EXPECT_LT(sum.norm(), 1e-12 * scale);
  EXPECT_LT(torque.norm(), 1e-12 * scale * x.cwiseAbs().maxCoeff());
}

TEST_P(ForcesTest, AnyNumberOfThreadsGivesTheSameForcesAsOne) {
  // with 7 chunks of ~11 points each chunk's stencils reach into several others' points
  const Model model = make_model(GetParam());
  const Points u = test::random_field(model.n_points, 0.1 * spacing, 23);
  const Points f1 = forces(model, u, 1);
  for (int threads : {2, 3, 7}) {
    const Points fn = forces(model, u, threads);
    EXPECT_LT((f1 - fn).norm(), 1e-12 * f1.norm()) << threads << " threads";
  }
}

INSTANTIATE_TEST_SUITE_P(
    Terms, ForcesTest,
    ::testing::Values(
        Config{"elastic_only", 0.0, 0.0}, Config{"with_volume", 3e5, 0.0}, Config{"with_hourglass", 0.0, 0.05},
        Config{"all_terms", 3e5, 0.2}, Config{"spiky", 1e5, 0.05, KernelType::SPIKY},
        Config{"viscosity", 1e5, 0.05, KernelType::VISCOSITY},
        Config{"quadratic_wide", 1e5, 0.05, KernelType::QUADRATIC, VolumeMode::CELL, 2.6},
        Config{"kernel_volumes", 1e5, 0.05, KernelType::POLY6, VolumeMode::KERNEL},
        // each model through the force loop's four-point stresses (lanes.hpp)
        Config{"neo_hookean", 0.0, 0.05, KernelType::POLY6, VolumeMode::CELL, 2.0, MaterialModel::NEO_HOOKEAN},
        Config{"mooney_rivlin", 3e5, 0.05, KernelType::POLY6, VolumeMode::CELL, 2.0, MaterialModel::MOONEY_RIVLIN},
        Config{"corotated", 0.0, 0.05, KernelType::POLY6, VolumeMode::CELL, 2.0, MaterialModel::COROTATED}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(Deformation, AffineFieldGivesItsExactGradientEverywhere) {
  for (double jitter : {0.0, 0.25}) {
    const Model model = make_model(Config{"all", 1e5, 0.05}, jitter);
    ASSERT_EQ(model.diagnostics.regularised_neighbourhoods, 0);
    Mat3 A;
    A << 0.1, -0.03, 0.02, 0.05, -0.07, 0.01, -0.02, 0.04, 0.09;
    const Vec3 b(0.001, -0.002, 0.003);
    Points u(3, model.n_points);
    for (index_t i = 0; i < model.n_points; ++i) u.col(i) = A * model.X.col(i) + b;
    // every point of a 5 x 4 x 4 grid is near the boundary: first-order consistency holds for all
    for (index_t i = 0; i < model.n_points; ++i)
      EXPECT_LT((displacement_gradient(model, u, i) - A).cwiseAbs().maxCoeff(), 1e-12) << "point " << i;
    // the hourglass penalty vanishes for affine fields
    EXPECT_LT(strain_energy(model, u).hourglass, 1e-12 * strain_energy(model, u).elastic);
  }
}

TEST(ZeroEnergyModes, OddEvenFieldIsOnlyResistedWithThePenalty) {
  // on a regular grid, u_j = (-1)^(a+b+c) e has zero strain at every interior point
  const PointCloud cloud = sample_box(Vec3::Zero(), Vec3::Constant(8 * spacing), spacing);
  MaterialParams m;
  for (double alpha : {0.0, 0.05}) {
    m.hourglass = alpha;
    const Model model = build_model(cloud, m, KernelParams{});
    Points u(3, model.n_points);
    const Vec3 e(0.3, -0.5, 0.8);
    for (index_t i = 0; i < model.n_points; ++i) {
      const Eigen::Vector3i abc = (model.X.col(i) / spacing).array().round().cast<int>();
      u.col(i) = ((abc.sum() % 2) ? -1.0 : 1.0) * 1e-3 * spacing * e;
    }
    // energy of the interior stencils (those with all 26 neighbours)
    double elastic = 0, penalty = 0;
    for (index_t i = 0; i < model.n_points; ++i) {
      if (model.neighbours.row_size(i) != 26) continue;
      const Mat3 G = displacement_gradient(model, u, i);
      const Mat3 E = green_strain(G);
      elastic +=
          model.volume[i] * 0.5 * (StVenantKirchhoff{model.lambda, model.mu}.second_piola(E).array() * E.array()).sum();
      for (index_t k = model.neighbours.begin(i); k < model.neighbours.end(i); ++k) {
        const index_t j = model.neighbours.index[k];
        const Mat3 G_mean = 0.5 * (G + displacement_gradient(model, u, j));
        penalty +=
            0.5 * model.hg_coef[k] * (u.col(j) - u.col(i) - G_mean * (model.X.col(j) - model.X.col(i))).squaredNorm();
      }
    }
    // what the same amplitude costs as a uniform 0.1% stretch of the interior
    const double interior_volume = 7 * 7 * 7 * spacing * spacing * spacing;
    const double stretch_energy = 0.5 * (model.lambda + 2 * model.mu) * 1e-6 * interior_volume;
    EXPECT_LT(elastic, 1e-20 * stretch_energy) << "alpha " << alpha;
    if (alpha == 0.0) {
      EXPECT_EQ(penalty, 0.0);
      // ... so the whole object resists the mode only through its surface stencils
    } else {
      EXPECT_GT(penalty, 0.05 * stretch_energy) << "alpha " << alpha;
    }
  }
}

}  // namespace
}  // namespace pointhaptics
