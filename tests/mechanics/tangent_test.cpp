// Tests for mechanics/tangent: the matrix-free Hessian-vector product against central differences of the
// forces, its symmetry, its diagonal blocks, and the positive semi-definite projection.
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/mechanics/tangent.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

struct Config {
  const char* name;
  double volume_stiffness;  // Pa
  double hourglass;
  KernelType kernel = KernelType::POLY6;
  double support_factor = 2.0;
};

std::ostream& operator<<(std::ostream& os, const Config& c) { return os << c.name; }

const double spacing = 0.01;

Model make_model(const Config& c, int nx = 5, int ny = 4, int nz = 4) {
  MaterialParams m;
  m.young = 1e5;
  m.poisson = 0.4;
  m.volume_stiffness = c.volume_stiffness;
  m.hourglass = c.hourglass;
  KernelParams k;
  k.type = c.kernel;
  k.support_factor = c.support_factor;
  return build_model(test::jittered_box(nx, ny, nz, spacing, 0.2), m, k);
}

Points forces(const Model& model, const Points& u) {
  Workspace ws(model, 1);
  compute_internal_forces(model, u, ws);
  return ws.f_int;
}

Points tangent_product(const Model& model, const Tangent& K, const Points& du, int threads = 1) {
  Workspace ws(model, threads);
  Points out(3, model.n_points);
  K.apply(model, du, ws, out);
  return out;
}

class TangentTest : public ::testing::TestWithParam<Config> {};

TEST_P(TangentTest, EqualsCentralDifferencesOfTheForces) {
  const Model model = make_model(GetParam());
  for (double scale : {0.02, 0.2}) {  // small and large deformation
    const Points u = test::random_field(model.n_points, scale * spacing, 21);
    Tangent K;
    K.linearise(model, u, TangentMode::EXACT);
    for (unsigned seed : {5u, 6u, 7u}) {
      const Points du = test::random_field(model.n_points, spacing, seed);
      const double eps = 1e-6;
      const Points fd = (forces(model, u - eps * du) - forces(model, u + eps * du)) / (2 * eps);
      const Points Kdu = tangent_product(model, K, du);
      EXPECT_LE((Kdu - fd).norm(), 1e-6 * fd.norm()) << "scale " << scale << " seed " << seed;
    }
  }
}

TEST_P(TangentTest, IsSymmetricAndThreadIndependent) {
  const Model model = make_model(GetParam());
  const Points u = test::random_field(model.n_points, 0.1 * spacing, 22);
  Tangent K;
  K.linearise(model, u, TangentMode::EXACT);
  const Points a = test::random_field(model.n_points, 1.0, 8), b = test::random_field(model.n_points, 1.0, 9);
  const Points Ka = tangent_product(model, K, a), Kb = tangent_product(model, K, b);
  const double ab = (b.array() * Ka.array()).sum(), ba = (a.array() * Kb.array()).sum();
  EXPECT_NEAR(ab, ba, 1e-10 * (std::abs(ab) + Ka.norm() * b.norm()));
  for (int threads : {2, 3, 7})
    EXPECT_LE((tangent_product(model, K, a, threads) - Ka).norm(), 1e-12 * Ka.norm()) << threads << " threads";
}

TEST_P(TangentTest, DiagonalBlocksMatchTheProductOnUnitVectors) {
  // also with passive points (the frozen ring of a level-of-detail model: neighbours without a stencil)
  // and on a workspace's 3 threads. The hourglass part of a block comes from the model, which counts the
  // passive points' pairs too (tangent.hpp), so with passive points only the other terms are exact.
  for (index_t passive : {0, 7}) {
    if (passive > 0 && GetParam().hourglass > 0) continue;
    Model model = make_model(GetParam(), 4, 3, 3);
    model.n_passive = passive;
    const Points u = test::random_field(model.n_points, 0.1 * spacing, 23);
    for (TangentMode mode : {TangentMode::EXACT, TangentMode::PROJECTED}) {
      Tangent K;
      K.linearise(model, u, mode);
      Eigen::Matrix<double, 9, Eigen::Dynamic> blocks, blocks_on_workspace;
      K.diagonal_blocks(model, blocks);
      Workspace ws(model, 3);
      K.diagonal_blocks(model, blocks_on_workspace, &ws);
      EXPECT_LE((blocks - blocks_on_workspace).norm(), 1e-12 * blocks.norm());
      for (index_t j = 0; j < model.n_points; ++j)
        for (int b = 0; b < 3; ++b) {
          Points e = Points::Zero(3, model.n_points);
          e(b, j) = 1.0;
          const Vec3 column = tangent_product(model, K, e).col(j);
          const Vec3 expected = Eigen::Map<const Mat3>(blocks.col(j).data()).col(b);
          EXPECT_LE((column - expected).norm(), 1e-10 * column.norm() + 1e-12)
              << "point " << j << " dof " << b << ", " << passive << " passive";
        }
    }
  }
}

const Config configs[] = {
    {"elastic", 0.0, 0.0},
    {"elastic_volume", 2e5, 0.0},
    {"elastic_hourglass", 0.0, 0.05},
    {"all_terms", 2e5, 0.05},
    {"spiky_wide", 1e5, 0.05, KernelType::SPIKY, 2.5},
};
INSTANTIATE_TEST_SUITE_P(Configs, TangentTest, ::testing::ValuesIn(configs),
                         [](const auto& info) { return std::string(info.param.name); });

// The full matrix of a small model, column by column.
Eigen::MatrixXd dense(const Model& model, const Tangent& K) {
  const Eigen::Index n = 3 * model.n_points;
  Eigen::MatrixXd A(n, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    Points e = Points::Zero(3, model.n_points);
    e.data()[k] = 1.0;
    A.col(k) = tangent_product(model, K, e).reshaped();
  }
  return A;
}

TEST(TangentProjection, IsPositiveSemiDefiniteWhereTheExactTangentIsNot) {
  const Model model = make_model({"all_terms", 2e5, 0.05}, 4, 3, 3);
  // a strong uniform compression (-30% along x) with noise: the geometric term makes K indefinite
  Points u = test::random_field(model.n_points, 0.02 * spacing, 24);
  u.row(0) += -0.3 * model.X.row(0);
  Tangent exact, projected;
  exact.linearise(model, u, TangentMode::EXACT);
  projected.linearise(model, u, TangentMode::PROJECTED);
  const Eigen::MatrixXd Ke = dense(model, exact), Kp = dense(model, projected);
  const double scale = Ke.norm();
  EXPECT_LT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (Ke + Ke.transpose())).eigenvalues().minCoeff(),
            -1e-6 * scale);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (Kp + Kp.transpose())).eigenvalues().minCoeff(),
            -1e-10 * scale);
}

TEST(TangentProjection, EqualsTheExactTangentUnderTension) {
  Config c{"elastic_hourglass", 0.0, 0.05};
  const Model model = make_model(c);
  Points u = Points::Zero(3, model.n_points);
  u.row(0) = 0.05 * model.X.row(0);  // uniform stretch along x: S is positive semi-definite
  u.row(1) = 0.02 * model.X.row(1);
  Tangent exact, projected;
  exact.linearise(model, u, TangentMode::EXACT);
  projected.linearise(model, u, TangentMode::PROJECTED);
  const Points du = test::random_field(model.n_points, 1.0, 10);
  const Points a = tangent_product(model, exact, du), b = tangent_product(model, projected, du);
  EXPECT_LE((a - b).norm(), 1e-10 * a.norm());
}

}  // namespace
}  // namespace pointhaptics
