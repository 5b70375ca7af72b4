// Tests for reduction/modal_basis and reduction/svk_polynomial: the basis is mass-orthonormal, zero at held points
// and spans the static response to its loads; the reduced energy, gradient and Hessian are exactly the full point
// model's energy, forces and tangent projected on the basis (for St. Venant-Kirchhoff the polynomial is exact), and
// models whose energy is not a polynomial are refused by name.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/mechanics/tangent.hpp>
#include <pointhaptics/reduction/modal_basis.hpp>
#include <pointhaptics/reduction/svk_polynomial.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

#include <random>

namespace pointhaptics {
namespace {

constexpr double spacing = 0.01;

// a 12 x 4 x 4 cantilever of St. Venant-Kirchhoff points, held at x = 0
Model cantilever(MaterialModel material = MaterialModel::SVK) { return test::jittered_cantilever(spacing, material); }

Points tip_load(const Model& model, double force) {
  Points f = Points::Zero(3, model.n_points);
  int n = 0;
  for (index_t i = 0; i < model.n_points; ++i) n += model.X(0, i) > 10.5 * spacing;
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.X(0, i) > 10.5 * spacing) f(1, i) = -force / n;
  return f;
}

Eigen::Map<const Eigen::VectorXd> flat(const Points& p) { return {p.data(), p.size()}; }

TEST(ModalBasis, IsMassOrthonormalAndZeroWhereHeld) {
  const Model model = cantilever();
  Workspace ws(model, 2);
  ModalBasisSettings settings;
  settings.size = 12;
  settings.loads = {tip_load(model, 0.01)};
  const ModalBasis basis = build_modal_basis(model, settings, ws);
  ASSERT_EQ(basis.U.cols(), 12);
  ASSERT_EQ(basis.U.rows(), 3 * model.n_points);
  Eigen::VectorXd mass(3 * model.n_points);
  for (index_t i = 0; i < model.n_points; ++i) mass.segment<3>(3 * i).setConstant(model.mass[i]);
  const Eigen::MatrixXd gram = basis.U.transpose() * mass.asDiagonal() * basis.U;
  EXPECT_LT((gram - Eigen::MatrixXd::Identity(12, 12)).cwiseAbs().maxCoeff(), 1e-10);
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.fixed[static_cast<std::size_t>(i)]) {
      EXPECT_EQ(basis.U.middleRows<3>(3 * i).cwiseAbs().maxCoeff(), 0.0);
    }
  // the modes ascend, and the first is a bending mode (its tip moves most in y or z)
  for (Eigen::Index k = 1; k < basis.eigenvalues.size(); ++k) EXPECT_GE(basis.eigenvalues[k], basis.eigenvalues[k - 1]);
  EXPECT_GT(basis.eigenvalues[0], 0);
  EXPECT_GT(basis.derivatives, 0);
  EXPECT_EQ(basis.load_vectors, 1);
  // U U^T M projects on the span
  const Eigen::MatrixXd projector = basis.U * basis.U.transpose() * mass.asDiagonal();
  // a field in the span is its own projection; a random one is not
  const Eigen::VectorXd in_span = basis.U * Eigen::VectorXd::LinSpaced(12, 1, 2);
  EXPECT_LT((projector * in_span - in_span).norm(), 1e-9 * in_span.norm());
  const Points noise = test::random_field(model.n_points, 1.0);
  EXPECT_GT((projector * flat(noise) - flat(noise)).norm(), 0.5 * flat(noise).norm());
}

TEST(ModalBasis, RefusesAnObjectWithNothingHeldOrTooFewDegreesOfFreedom) {
  Model model = cantilever();
  Workspace ws(model, 2);
  std::fill(model.fixed.begin(), model.fixed.end(), 0);
  ModalBasisSettings settings;
  EXPECT_THROW(build_modal_basis(model, settings, ws), Error);
  Model held = cantilever();
  settings.size = 3 * static_cast<int>(held.n_points);
  EXPECT_THROW(build_modal_basis(held, settings, ws), Error);
}

TEST(ModalBasis, ACoarseSamplingKeepsTheVolumeTheLoadsAndTheHeldFace) {
  Model model = cantilever();
  model.f_ext = tip_load(model, 0.01);
  const Model coarse = coarse_model(model, 2 * spacing);
  EXPECT_LT(coarse.n_points, model.n_points / 2);
  EXPECT_GT(coarse.n_points, model.n_points / 12);
  EXPECT_NEAR(coarse.volume.sum(), model.volume.sum(), 1e-12 * model.volume.sum());
  EXPECT_NEAR(coarse.f_ext.row(1).sum(), -0.01, 1e-15);
  int held = 0;
  for (index_t i = 0; i < coarse.n_points; ++i)
    if (coarse.fixed[static_cast<std::size_t>(i)]) {
      ++held;
      EXPECT_LT(coarse.X(0, i), 0.5 * spacing);
    }
  EXPECT_GT(held, 0);
  EXPECT_THROW(coarse_model(model, 0.5 * spacing), Error);
  // its basis carried to the points: mass-orthonormal and zero where held there
  Workspace ws(coarse, 2);
  ModalBasisSettings settings;
  settings.size = 8;
  settings.loads = {coarse.f_ext};
  const ModalBasis carried = carry_basis(build_modal_basis(coarse, settings, ws), coarse, model);
  ASSERT_EQ(carried.U.rows(), 3 * model.n_points);
  Eigen::VectorXd mass(3 * model.n_points);
  for (index_t i = 0; i < model.n_points; ++i) mass.segment<3>(3 * i).setConstant(model.mass[i]);
  EXPECT_LT(
      (carried.U.transpose() * mass.asDiagonal() * carried.U - Eigen::MatrixXd::Identity(8, 8)).cwiseAbs().maxCoeff(),
      1e-10);
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.fixed[static_cast<std::size_t>(i)]) {
      EXPECT_EQ(carried.U.middleRows<3>(3 * i).cwiseAbs().maxCoeff(), 0.0);
    }
}

class SvkPolynomialTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ModalBasisSettings settings;
    settings.size = 8;
    basis = build_modal_basis(model, settings, ws);
  }
  // coordinates whose displacement reaches about `size` m
  Eigen::VectorXd coordinates(double size, unsigned seed) const {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise;
    Eigen::VectorXd q(basis.U.cols());
    for (Eigen::Index k = 0; k < q.size(); ++k) q[k] = noise(rng);
    return q * (size / (basis.U * q).cwiseAbs().maxCoeff());
  }
  Model model = cantilever();
  Workspace ws{model, 2};
  ModalBasis basis;
};

TEST_F(SvkPolynomialTest, EnergyIsTheFullModelsAtTheSameDisplacement) {
  const SvkPolynomial polynomial(model, basis.U, ws);
  EXPECT_EQ(polynomial.size(), 8);
  // up to large strains (the tip moves by half the beam's height), where all four orders matter
  for (double size : {1e-4, 3e-3, 2e-2}) {
    const Eigen::VectorXd q = coordinates(size, 7);
    const double full = strain_energy(model, displacement_of(basis.U, q, model.n_points)).total();
    EXPECT_NEAR(polynomial.energy(q), full, 1e-10 * full) << "size " << size;
  }
  EXPECT_DOUBLE_EQ(polynomial.energy(Eigen::VectorXd::Zero(8)), 0.0);
}

TEST_F(SvkPolynomialTest, GradientIsTheProjectedForcesAndHessianTheProjectedTangent) {
  const SvkPolynomial polynomial(model, basis.U, ws);
  const Eigen::VectorXd q = coordinates(1e-2, 11);
  const Points u = displacement_of(basis.U, q, model.n_points);
  Eigen::VectorXd gradient;
  Eigen::MatrixXd hessian;
  polynomial.evaluate(q, gradient, &hessian);
  compute_internal_forces(model, u, ws);  // ws.f_int = -dW/du
  const Eigen::VectorXd projected = -(basis.U.transpose() * flat(ws.f_int));
  EXPECT_LT((gradient - projected).norm(), 1e-9 * projected.norm());
  Tangent tangent;
  tangent.linearise(model, u, TangentMode::EXACT, &ws);
  Eigen::MatrixXd full(8, 8);
  Points column(3, model.n_points), image(3, model.n_points);
  for (int k = 0; k < 8; ++k) {
    column = Eigen::Map<const Points>(basis.U.col(k).data(), 3, model.n_points);
    tangent.apply(model, column, ws, image);
    full.col(k) = basis.U.transpose() * flat(image);
  }
  EXPECT_LT((hessian - full).norm(), 1e-9 * full.norm());
  EXPECT_LT((hessian - hessian.transpose()).norm(), 1e-12 * hessian.norm());
  // evaluating again gives the same (the scratch is reused, not accumulated)
  Eigen::VectorXd again;
  polynomial.evaluate(q, again, nullptr);
  EXPECT_EQ(again, gradient);
}

TEST(SvkPolynomial, RefusesEnergiesThatAreNotPolynomials) {
  Model neo = cantilever(MaterialModel::NEO_HOOKEAN);
  Workspace ws(neo, 2);
  const Eigen::MatrixXd U = Eigen::MatrixXd::Identity(3 * neo.n_points, 2);
  EXPECT_THROW(SvkPolynomial(neo, U, ws), Error);
  Model volume = cantilever();
  volume.material.volume_stiffness = 1e4;
  EXPECT_THROW(SvkPolynomial(volume, U, ws), Error);
  Model svk = cantilever();
  EXPECT_THROW(SvkPolynomial(svk, Eigen::MatrixXd::Identity(5, 2), ws), Error);
}

}  // namespace
}  // namespace pointhaptics
