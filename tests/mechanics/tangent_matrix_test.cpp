// Tests for mechanics/tangent_matrix: the assembled tangent equals the matrix-free one (Tangent::apply) block
// for block, is symmetric, and its hourglass part bounds the penalty's exact Hessian from above while leaving
// linear fields (which the penalty never resists) free.
#include <pointhaptics/mechanics/tangent.hpp>
#include <pointhaptics/mechanics/tangent_matrix.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

const double spacing = 0.01;

Model make_model(MaterialModel material, double hourglass) {
  MaterialParams m;
  m.model = material;
  m.young = 1e5;
  m.poisson = 0.4;
  m.hourglass = hourglass;
  return build_model(test::jittered_box(5, 4, 4, spacing, 0.2), m, KernelParams{});
}

Points product(const TangentMatrix& K, const Points& x) {
  Points y;
  multiply(K, x, y);
  return y;
}

TangentMatrix assembled(const Model& model, const Tangent& tangent) {
  TangentMatrix K;
  assemble_tangent(model, tangent, K);
  return K;
}

Points matrix_free(const Model& model, const Tangent& tangent, const Points& x) {
  Workspace ws(model, 2);
  Points y(3, model.n_points);
  tangent.apply(model, x, ws, y);
  return y;
}

TEST(TangentMatrix, EqualsTheMatrixFreeTangentWithoutTheHourglass) {
  for (MaterialModel material : {MaterialModel::SVK, MaterialModel::NEO_HOOKEAN}) {
    for (TangentMode mode : {TangentMode::EXACT, TangentMode::PROJECTED}) {
      const Model model = make_model(material, 0.0);
      Tangent tangent;
      tangent.linearise(model, test::random_field(model.n_points, 0.2 * spacing, 4), mode);
      const TangentMatrix K = assembled(model, tangent);
      for (unsigned seed : {7u, 8u}) {
        const Points x = test::random_field(model.n_points, spacing, seed);
        const Points expected = matrix_free(model, tangent, x);
        EXPECT_LT((product(K, x) - expected).norm(), 1e-10 * expected.norm()) << enum_name(material);
      }
    }
  }
}

TEST(TangentMatrix, IsSymmetricBlockForBlock) {
  const Model model = make_model(MaterialModel::NEO_HOOKEAN, 0.3);
  Tangent tangent;
  tangent.linearise(model, test::random_field(model.n_points, 0.2 * spacing, 4), TangentMode::PROJECTED);
  const TangentMatrix K = assembled(model, tangent);
  double scale = 0, asymmetry = 0;
  for (index_t j = 0; j < K.pattern.n_rows(); ++j)
    for (index_t e = K.pattern.begin(j); e < K.pattern.end(j); ++e) {
      const index_t k = K.pattern.index[e];
      const auto* row_k = &K.pattern.index[K.pattern.begin(k)];
      const index_t f =
          K.pattern.begin(k) + static_cast<index_t>(std::lower_bound(row_k, row_k + K.pattern.row_size(k), j) - row_k);
      ASSERT_EQ(K.pattern.index[f], j) << "the pattern is symmetric";
      const Mat3 Kjk = Eigen::Map<const Mat3>(K.values.data() + 9 * static_cast<std::size_t>(e));
      const Mat3 Kkj = Eigen::Map<const Mat3>(K.values.data() + 9 * static_cast<std::size_t>(f));
      asymmetry = std::max(asymmetry, (Kjk - Kkj.transpose()).cwiseAbs().maxCoeff());
      scale = std::max(scale, Kjk.cwiseAbs().maxCoeff());
    }
  EXPECT_LT(asymmetry, 1e-10 * scale);
}

TEST(TangentMatrix, TheHourglassPartBoundsThePenaltysHessianAndLeavesLinearFieldsFree) {
  const Model with = make_model(MaterialModel::SVK, 0.3), without = make_model(MaterialModel::SVK, 0.0);
  Tangent tangent;
  tangent.linearise(with, Points::Zero(3, with.n_points), TangentMode::EXACT);
  Tangent elastic;
  elastic.linearise(without, Points::Zero(3, without.n_points), TangentMode::EXACT);
  const TangentMatrix K = assembled(with, tangent), K0 = assembled(without, elastic);
  for (unsigned seed : {11u, 12u, 13u}) {
    const Points x = test::random_field(with.n_points, spacing, seed);
    // x^T H x of the penalty's exact Hessian and of the assembled bound
    const double exact = (x.array() * (matrix_free(with, tangent, x) - matrix_free(without, elastic, x)).array()).sum();
    const double bound = (x.array() * (product(K, x) - product(K0, x)).array()).sum();
    EXPECT_GT(exact, 0);
    EXPECT_GE(bound, exact * (1 - 1e-12));
    EXPECT_LT(bound, 4 * exact) << "a bound, but a close one";
  }
  // a linear field u = A X: every pair residual vanishes (the stencils reproduce linear fields)
  Mat3 A;
  A << 0.01, 0.02, -0.01, 0.005, -0.02, 0.01, 0.0, 0.01, 0.03;
  const Points x = A * with.X;
  const Points hourglass = product(K, x) - product(K0, x);
  EXPECT_LT(hourglass.norm(), 1e-8 * product(K0, x).norm() + 1e-12);
}

// A coupling a S between two points enters both off-diagonal blocks where the pattern has them, and is
// lumped onto the two diagonal blocks as |a| S where it has not; either way x^T K x only grows by at least
// a x_j^T S x_k (the lumped form bounds it from above).
TEST(TangentMatrix, ACouplingEntersItsBlocksOrIsLumpedOntoTheDiagonal) {
  const Model model = make_model(MaterialModel::SVK, 0);
  TangentMatrix K;
  build_tangent_pattern(model, K);
  const auto is_block = [&](index_t j, index_t k) {
    for (index_t e = K.pattern.begin(j); e < K.pattern.end(j); ++e)
      if (K.pattern.index[e] == k) return e;
    return index_t{-1};
  };
  index_t near = -1, far = -1;
  for (index_t k = 1; k < model.n_points; ++k) {
    if (near < 0 && is_block(0, k) >= 0) near = k;
    if (far < 0 && is_block(0, k) < 0) far = k;
  }
  ASSERT_GE(near, 0);
  ASSERT_GE(far, 0) << "the box is wider than two stencils";
  Mat3 S;
  S << 2, 0.5, 0, 0.5, 1, 0.2, 0, 0.2, 3;  // symmetric positive definite
  const auto block = [&](index_t e) {
    return Mat3(Eigen::Map<const Mat3>(K.values.data() + 9 * static_cast<std::size_t>(e)));
  };
  for (const double a : {0.7, -0.7}) {
    SCOPED_TRACE(a);
    K.values.assign(9 * static_cast<std::size_t>(K.n_blocks()), 0.0);
    add_coupling(K, 0, near, a, S);
    EXPECT_TRUE(block(is_block(0, near)).isApprox(a * S));
    EXPECT_TRUE(block(is_block(near, 0)).isApprox(a * S));
    EXPECT_EQ(block(K.diagonal[0]).norm(), 0.0);
    K.values.assign(9 * static_cast<std::size_t>(K.n_blocks()), 0.0);
    add_coupling(K, 0, far, a, S);
    EXPECT_TRUE(block(K.diagonal[0]).isApprox(std::abs(a) * S));
    EXPECT_TRUE(block(K.diagonal[far]).isApprox(std::abs(a) * S));
    const Points x = test::random_field(model.n_points, 1.0, 3);
    const double exact = a * (x.col(0).dot(S * x.col(far)) + x.col(far).dot(S * x.col(0)));
    EXPECT_GE(x.cwiseProduct(product(K, x)).sum(), exact);
  }
  K.values.assign(9 * static_cast<std::size_t>(K.n_blocks()), 0.0);
  add_coupling(K, 4, 4, 0.5, S);
  EXPECT_TRUE(block(K.diagonal[4]).isApprox(0.5 * S)) << "a point with itself: once";
}

}  // namespace
}  // namespace pointhaptics
