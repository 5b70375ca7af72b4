// Viscoelasticity (issue 17, item 5): a Prony series on the shear part of any material. The integrator
// against the closed form of a held stretch at finite strain; the overstress term against finite
// differences; and a bar in explicit and implicit dynamics against the standard linear solid's closed-form
// relaxation (held stretch) and creep (held load).
#include <pointhaptics/geometry/sampling.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/mechanics/energies/material.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>
#include <pointhaptics/mechanics/viscoelasticity.hpp>
#include <pointhaptics/session/scene_session.hpp>

#include <gtest/gtest.h>
#include <fmt/format.h>

#include <cmath>
#include <random>

namespace pointhaptics {
namespace {

TEST(Prony, StepCoefficientsRelaxToTheSeriesShareAndJoinAtTheSeriesSwitch) {
  const std::vector<PronyTerm> series{{0.3, 0.2}, {0.25, 5.0}};
  for (const double dt : {1e-7, 1e-4, 2e-4 * (1 - 1e-12), 2e-4 * (1 + 1e-12), 0.01, 1.0, 100.0}) {
    const PronyStep s = prony_step(series, dt);
    ASSERT_EQ(s.terms, 2u);
    for (std::size_t k = 0; k < 2; ++k) {
      // b + c = g (1 - a): a held shear stress relaxes Q to g S
      const double relaxing = -series[k].g * std::expm1(-dt / series[k].tau);  // g (1 - a)
      EXPECT_NEAR(s.b[k] + s.c[k], relaxing, 1e-12 * relaxing) << dt;
      EXPECT_GE(s.b[k], 0.0);
      EXPECT_GE(s.c[k], 0.0);
      EXPECT_LT(s.a[k], 1.0);
    }
  }
  // the short-step series and the closed form meet where the code switches (x = 1e-3)
  const PronyStep below = prony_step({{0.5, 1.0}}, 1e-3 * (1 - 1e-14)),
                  above = prony_step({{0.5, 1.0}}, 1e-3 * (1 + 1e-14));
  EXPECT_NEAR(below.c[0] / above.c[0], 1.0, 1e-11);
  EXPECT_NEAR(below.b[0] / above.b[0], 1.0, 1e-11);
}

// a small cube: interior points have full stencils; every point follows the affine field u = (F - I) X
Model cube(MaterialModel kind, std::vector<PronyTerm> prony) {
  MaterialParams m;
  m.model = kind;
  m.young = 1e4;
  m.poisson = 0.3;
  m.prony = std::move(prony);
  return build_model(sample_box(Vec3::Zero(), Vec3::Constant(0.04), 0.01), m, KernelParams{});
}

Points affine(const Model& model, const Mat3& F) { return (F - Mat3::Identity()) * model.X; }

// The second Piola-Kirchhoff stress the force loop uses at point i within the current step (Workspace's)
Mat3 step_stress(const Model& model, const Workspace& ws, const Mat3& G, index_t i) {
  return with_material(model, viscous_step(ws), [&](const auto& energy) {
    const Mat3 F = Mat3::Identity() + G;
    return Mat3(F.inverse() * energy.stress(i, G));
  });
}

class HeldStretch : public ::testing::TestWithParam<MaterialModel> {};

TEST_P(HeldStretch, RelaxesAsTheClosedFormAtFiniteStrain) {
  // a 30% stretch applied over the first step and held: S(t) = S_el - sum_k Q_k(t) with, for a ramp over dt,
  //   Q_k(t) = g_k S_s [1 - (tau_k / dt) (e^(-(t - dt)/tau_k) - e^(-t/tau_k))]
  const std::vector<PronyTerm> series{{0.3, 0.05}, {0.2, 0.5}};
  const Model model = cube(GetParam(), series);
  Workspace ws(model, 1);
  State state = State::at_rest(model);
  Mat3 F = Mat3::Identity();
  F(0, 0) = 1.3;
  F(0, 1) = 0.1;  // and some shear
  state.u = affine(model, F);
  const index_t centre = model.n_points / 2;  // the cube's middle point (5 x 5 x 5 lattice)
  const Mat3 G = F - Mat3::Identity();
  const Mat3 S_el = step_stress(model, ws, G, centre);  // no step begun: the instantaneous elastic stress
  const Mat3 S_shear = shear_stress(model, centre, G);
  double t = 0;
  for (const double dt : {0.01, 0.01, 0.02, 0.05, 0.1, 0.3, 0.5}) {  // variable steps
    begin_viscous_step(model, state, dt, ws);
    t += dt;
    const Mat3 S = step_stress(model, ws, G, centre);
    end_viscous_step(model, dt, state, ws);
    Mat3 expected = S_el;
    for (const PronyTerm& k : series) {
      const double ramp = 0.01;
      expected -= k.g * S_shear * (1 - k.tau / ramp * (std::exp(-(t - ramp) / k.tau) - std::exp(-t / k.tau)));
    }
    EXPECT_LT((S - expected).norm(), 1e-10 * S_el.norm()) << "t = " << t << "\n" << S << "\n" << expected;
  }
  // the relaxed shear share is exactly the series' (the volume response does not relax)
  relaxed_material(model, ws);
  const Mat3 S_long = step_stress(model, ws, G, centre);
  EXPECT_LT((S_long - (S_el - 0.5 * S_shear)).norm(), 1e-10 * S_el.norm());
}

INSTANTIATE_TEST_SUITE_P(Models, HeldStretch,
                         ::testing::Values(MaterialModel::SVK, MaterialModel::NEO_HOOKEAN, MaterialModel::MOONEY_RIVLIN,
                                           MaterialModel::COROTATED),
                         [](const auto& info) { return std::string(to_string(info.param)); });

TEST(ShearStress, IsTheDeviatoricStressAtSmallStrainAndFrameInvariant) {
  for (const MaterialModel kind :
       {MaterialModel::SVK, MaterialModel::NEO_HOOKEAN, MaterialModel::MOONEY_RIVLIN, MaterialModel::COROTATED}) {
    const Model model = cube(kind, {{0.5, 1.0}});
    const index_t centre = model.n_points / 2;
    // small strain: S_s = 2 mu dev(eps)
    Mat3 eps;
    eps << 1, 0.3, -0.2, 0.3, -0.5, 0.1, -0.2, 0.1, 0.7;
    eps *= 1e-7;
    const Mat3 dev = eps - eps.trace() / 3 * Mat3::Identity();
    const Mat3 S = shear_stress(model, centre, eps);
    EXPECT_LT((S - 2 * model.mu * dev).norm(), 1e-5 * (2 * model.mu * dev).norm()) << to_string(kind);
    // a rotation of the deformed state leaves the second Piola-Kirchhoff stress unchanged
    Mat3 F;
    F << 1.2, 0.1, 0.0, -0.2, 0.9, 0.15, 0.05, 0.0, 1.1;
    const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    const Mat3 S1 = shear_stress(model, centre, F - Mat3::Identity());
    const Mat3 S2 = shear_stress(model, centre, R * F - Mat3::Identity());
    EXPECT_LT((S1 - S2).norm(), 1e-10 * S1.norm()) << to_string(kind);
  }
}

TEST(ViscousStep, ForcesAreTheEnergysGradient) {
  // within a step the forces are -dPi/du of the step's energy (material with relaxed shear, overstress term)
  const Model model = cube(MaterialModel::NEO_HOOKEAN, {{0.4, 0.1}});
  Workspace ws(model, 1);
  State state = State::at_rest(model);
  Mat3 F;
  F << 1.1, 0.05, 0.0, 0.0, 0.95, 0.02, 0.03, 0.0, 1.05;
  state.u = affine(model, F);
  begin_viscous_step(model, state, 0.02, ws);
  end_viscous_step(model, 0.02, state, ws);  // some history
  begin_viscous_step(model, state, 0.03, ws);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise;
  Points u = state.u;
  for (Eigen::Index k = 0; k < u.size(); ++k) u.data()[k] += 1e-3 * noise(rng);
  compute_internal_forces(model, u, ws);
  const Points f = ws.f_int;
  Points du(3, model.n_points);
  for (Eigen::Index k = 0; k < du.size(); ++k) du.data()[k] = noise(rng);
  const double h = 1e-7;
  const double e_plus = strain_energy(model, u + h * du, nullptr, viscous_step(ws)).total();
  const double e_minus = strain_energy(model, u - h * du, nullptr, viscous_step(ws)).total();
  const double fd = (e_plus - e_minus) / (2 * h);
  const double exact = -(f.array() * du.array()).sum();
  EXPECT_NEAR(fd, exact, 1e-6 * std::abs(exact));
  EXPECT_NE(strain_energy(model, u, nullptr, viscous_step(ws)).viscous, 0.0);
}

TEST(ViscousStep, TheStepsEndStressIsTheStatesStress) {
  // the stress a step ends with (relaxed modulus, overstress from the history before) is the stress of the
  // state it leaves (elastic less the new history's sum of Q_k): reactions after a step need no step
  const Model model = cube(MaterialModel::MOONEY_RIVLIN, {{0.3, 0.05}, {0.25, 0.4}});
  Workspace ws(model, 2);
  State state = State::at_rest(model);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise;
  for (const double dt : {0.01, 0.03, 0.2}) {
    for (Eigen::Index k = 0; k < state.u.size(); ++k) state.u.data()[k] += 2e-4 * noise(rng);
    begin_viscous_step(model, state, dt, ws);
    compute_internal_forces(model, state.u, ws);
    const Points step_end = ws.f_int;
    end_viscous_step(model, dt, state, ws);
    viscous_stress_at_state(model, state, ws, false);
    compute_internal_forces(model, state.u, ws);
    EXPECT_LT((ws.f_int - step_end).norm(), 1e-10 * step_end.norm()) << dt;
  }
  // and a state that carries no history (made by hand) is taken as at rest, not read out of bounds
  State bare;
  bare.u = state.u;
  bare.velocity = state.velocity;
  begin_viscous_step(model, bare, 0.01, ws);
  EXPECT_EQ(ws.overstress.norm(), 0.0);
  end_viscous_step(model, 0.01, bare, ws);
  EXPECT_EQ(bare.viscous.rows(), 18);
  EXPECT_GT(bare.viscous.norm(), 0.0);
}

// ---- a bar in dynamics against the standard linear solid (one Prony term, small strain) ----
// G0 = mu, G_inf = (1 - g) mu, K fixed; uniaxial stress: E(t) = E_inf + (E0 - E_inf) e^(-t/tau_R),
// tau_R = tau (3K + G0) / (3K + G_inf); creep D(t) = 1/E_inf - (1/E_inf - 1/E0) e^(-t/tau_C), tau_C = tau_R E0 / E_inf.
struct StandardLinearSolid {
  double E0, E_inf, tau_R, tau_C;
  StandardLinearSolid(double young, double poisson, double g, double tau) {
    const double mu = young / (2 * (1 + poisson)), K = young / (3 * (1 - 2 * poisson));
    const double mu_inf = (1 - g) * mu;
    E0 = young;
    E_inf = 9 * K * mu_inf / (3 * K + mu_inf);
    tau_R = tau * (3 * K + mu) / (3 * K + mu_inf);
    tau_C = tau_R * E0 / E_inf;
  }
  /// stress over strain after a linear ramp of the strain over [0, ramp], t >= ramp
  double relaxation_after_ramp(double t, double ramp) const {
    return E_inf + (E0 - E_inf) * tau_R / ramp * (std::exp(-(t - ramp) / tau_R) - std::exp(-t / tau_R));
  }
  double creep_compliance(double t) const { return 1 / E_inf - (1 / E_inf - 1 / E0) * std::exp(-t / tau_C); }
};

const double young = 1e4, g = 0.4, tau = 0.5;

std::string bar_scene(const std::string& solver, double dt, const std::string& ends, bool viscous, double poisson) {
  return fmt::format(R"(
[object]
shape = "box"
size = [0.02, 0.08, 0.02]
spacing = 0.005
[material]
model = "neo_hookean"
young = {}
poisson = {}
damping = 40
{}
{}
[solver]
kind = "{}"
dt = {}
)",
                     young, poisson, viscous ? fmt::format("prony = [[{}, {}]]", g, tau) : "", ends, solver, dt);
}

// the mean y-displacement of the points at y = y0
double mean_uy(const Simulation& sim, double y0) {
  const Model& model = sim.model();
  double sum = 0;
  int n = 0;
  for (index_t i = 0; i < model.n_points; ++i)
    if (std::abs(model.X(1, i) - y0) < 1e-9) {
      sum += sim.state().u(1, i);
      ++n;
    }
  return sum / n;
}

// the bar's bottom held and its top moved by 0.1% of its length over 50 ms (dynamics), then held
const std::string held_stretch = R"(
[[fixed]]
box = { min = [-1, -1, -1], max = [1, 0, 1] }
[[fixed]]
box = { min = [-1, 0.08, -1], max = [1, 1, 1] }
displacement = [0, 8e-5, 0]
ramp = 0.05
)";

class Bar : public ::testing::TestWithParam<std::string> {};

TEST_P(Bar, CreepsUnderAHeldLoadAsTheClosedForm) {
  // a free bar pulled by equal and opposite end tractions from t = 0: uniaxial stress sigma0 = F / A.
  // The strain is taken against the elastic bar's own (the same model without the series, settled), which
  // takes out the discretisation's elastic error and leaves the time response
  const std::string ends = R"(
[[load]]
kind = "traction"
box = { min = [-1, 0.08, -1], max = [1, 1, 1] }
total = [0, 0.004, 0]
[[load]]
kind = "traction"
box = { min = [-1, -1, -1], max = [1, 0, 1] }
total = [0, -0.004, 0]
)";
  const double dt = GetParam() == "explicit" ? 1e-3 : 5e-3, poisson = 0.3;
  const StandardLinearSolid sls(young, poisson, g, tau);
  auto elongation = [](const Simulation& sim) { return mean_uy(sim, 0.08) - mean_uy(sim, 0.0); };
  SceneSession elastic = open_scene(parse_scene(bar_scene(GetParam(), dt, ends, false, poisson), "bar.toml"));
  elastic.simulation->run(0.5);
  const double elastic_elongation = elongation(*elastic.simulation);
  // the elastic bar itself: sigma0 L / E0 to the discretisation's accuracy
  EXPECT_NEAR(elastic_elongation / (0.004 / 4e-4 * 0.08 / young), 1.0, 0.02);
  SceneSession viscous = open_scene(parse_scene(bar_scene(GetParam(), dt, ends, true, poisson), "bar.toml"));
  Simulation& sim = *viscous.simulation;
  for (const double t : {0.3, 0.6, 1.0, 2.0, 4.0}) {
    sim.run(t - sim.time());
    const double expected = elastic_elongation * young * sls.creep_compliance(sim.time());
    EXPECT_NEAR(elongation(sim) / expected, 1.0, 0.01) << GetParam() << " t = " << sim.time();
    fmt::print("creep {} t = {:.3f}: {:.6e} expected {:.6e} ({:+.3f}%)\n", GetParam(), sim.time(), elongation(sim),
               expected, 100 * (elongation(sim) / expected - 1));
  }
  EXPECT_TRUE(sim.summary().converged);
}

TEST_P(Bar, RelaxesUnderAHeldStretchAsTheClosedForm) {
  // the bar's bottom held and its top moved by 0.1% of its length over 50 ms, then held: the top's
  // reaction against the elastic bar's, scaled by the closed form. The ends are bonded, so the bar is in
  // uniaxial stress only while it does not contract sideways: Poisson's ratio 0 at first, and as the shear
  // relaxes 0.154, whose end effect shows as +0.45% in the long term (as in the static test below)
  const std::string& ends = held_stretch;
  const double dt = GetParam() == "explicit" ? 1e-3 : 5e-3, poisson = 0.0;
  const StandardLinearSolid sls(young, poisson, g, tau);
  SceneSession elastic = open_scene(parse_scene(bar_scene(GetParam(), dt, ends, false, poisson), "bar.toml"));
  elastic.simulation->run(0.5);
  const double elastic_force = elastic.simulation->summary().reactions[1].y();
  SceneSession viscous = open_scene(parse_scene(bar_scene(GetParam(), dt, ends, true, poisson), "bar.toml"));
  Simulation& sim = *viscous.simulation;
  for (const double t : {0.3, 0.6, 1.0, 2.0, 4.0}) {  // the ramp's ringing has died down by 0.3 s
    sim.run(t - sim.time());
    const double force = sim.summary().reactions[1].y();
    const double expected = elastic_force * sls.relaxation_after_ramp(sim.time(), 0.05) / young;
    EXPECT_NEAR(force / expected, 1.0, 0.01) << GetParam() << " t = " << sim.time();
    fmt::print("relaxation {} t = {:.3f}: {:.6e} expected {:.6e} ({:+.3f}%)\n", GetParam(), sim.time(), force, expected,
               100 * (force / expected - 1));
  }
}

INSTANTIATE_TEST_SUITE_P(Solvers, Bar, ::testing::Values("explicit", "implicit"));

TEST(ViscousScene, StaticSolveIsTheLongTermEquilibrium) {
  // a static solve of a viscoelastic bar is the elastic bar with the long-term shear modulus (a static
  // solve applies the stretch at once: ramps are for dynamics)
  const std::string& ends = held_stretch;
  const double poisson = 0.0;
  SceneSession viscous = open_scene(parse_scene(bar_scene("static", 1e-3, ends, true, poisson), "bar.toml"));
  viscous.simulation->step();
  const double relaxed = viscous.simulation->summary().reactions[1].y();
  SceneSession elastic = open_scene(parse_scene(bar_scene("static", 1e-3, ends, false, poisson), "bar.toml"));
  elastic.simulation->step();
  const double instantaneous = elastic.simulation->summary().reactions[1].y();
  const StandardLinearSolid sls(young, poisson, g, tau);
  EXPECT_NEAR(relaxed / instantaneous, sls.E_inf / sls.E0, 0.006 * sls.E_inf / sls.E0);
}

}  // namespace
}  // namespace pointhaptics
