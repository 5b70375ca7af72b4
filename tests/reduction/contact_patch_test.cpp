// Tests for reduction/contact_patch (issue 49, item 2): the region a tool touches in full resolution, coupled to a
// reduced model. The patch's energy difference is exactly the full model's; the coupled energy's gradient is its
// derivative and its Hessian close to it; a probe pressing a reduced cantilever feels the full point model's force
// and bends it as far.
#include <pointhaptics/haptics/devices/virtual_device.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/model_patch.hpp>
#include <pointhaptics/reduction/contact_patch.hpp>
#include <pointhaptics/reduction/modal_basis.hpp>
#include <pointhaptics/reduction/reduced_solver.hpp>
#include <pointhaptics/session/interactive.hpp>
#include <pointhaptics/session/scene_session.hpp>
#include <pointhaptics/world/model_simulation.hpp>
#include <pointhaptics/world/simulation.hpp>

#include "support/test_models.hpp"
#include "support/test_scenes.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <random>

namespace pointhaptics {
namespace {

constexpr double spacing = 0.01;

// a 12 x 4 x 4 cantilever of St. Venant-Kirchhoff points, held at x = 0
Model cantilever() { return test::jittered_cantilever(spacing); }

// the top points near x = 8 spacings: where a tool presses
std::vector<index_t> pressed_points(const Model& model) {
  std::vector<index_t> out;
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.X(1, i) > 2.5 * spacing && std::abs(model.X(0, i) - 8 * spacing) < 1.2 * spacing &&
        std::abs(model.X(2, i) - 1.5 * spacing) < 1.2 * spacing)
      out.push_back(i);
  return out;
}

TEST(ContactPatch, ThePatchsEnergyChangeIsTheFullModelsForAnyCorrection) {
  // the claim the coupling rests on: moving the free points A by w changes the full model's energy exactly as it
  // changes the patch's (its stencils and hourglass pairs that see A are whole in it), at any u around it
  const Model model = cantilever();
  const std::vector<index_t> free = neighbourhood(model, pressed_points(model), 2);
  const ModelPatch patch = model_patch(model, free, 3);
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  Points u = Points::NullaryExpr(3, model.n_points, [&](Eigen::Index, Eigen::Index) { return 2e-3 * normal(rng); });
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.fixed[static_cast<std::size_t>(i)]) u.col(i).setZero();
  Points corrected = u;
  for (index_t k = 0; k < patch.n_free; ++k)
    if (!model.fixed[static_cast<std::size_t>(patch.full_of[static_cast<std::size_t>(k)])])
      corrected.col(patch.full_of[static_cast<std::size_t>(k)]) += Vec3(1e-3 * normal(rng), 1e-3 * normal(rng), 0);
  Points patch_u(3, patch.model.n_points), patch_corrected(3, patch.model.n_points);
  for (index_t k = 0; k < patch.model.n_points; ++k) {
    patch_u.col(k) = u.col(patch.full_of[static_cast<std::size_t>(k)]);
    patch_corrected.col(k) = corrected.col(patch.full_of[static_cast<std::size_t>(k)]);
  }
  const double full = strain_energy(model, corrected).total() - strain_energy(model, u).total();
  const double local =
      strain_energy(patch.model, patch_corrected).total() - strain_energy(patch.model, patch_u).total();
  EXPECT_NEAR(local, full, 1e-10 * std::abs(full)) << "full " << full << " patch " << local;
  EXPECT_GT(std::abs(full), 1e-8);
  // and so does the part of it that moves with A (its stencils and pairs within a ring of A), which the coupling
  // evaluates; a part missing a pair or a stencil is off by far more
  std::vector<Mat3> gradients;
  const auto near = [&](const Points& at) {
    return strain_energy_near(patch.model, at, patch.ring_end[0], patch.ring_end[1], gradients).total();
  };
  const double near_change = near(patch_corrected) - near(patch_u);
  EXPECT_NEAR(near_change, full, 1e-10 * std::abs(full)) << "full " << full << " near " << near_change;
  EXPECT_LT(std::abs(near(patch_u)), 0.9 * std::abs(strain_energy(patch.model, patch_u).total()));
}

struct Coupled {
  Model model = cantilever();
  ModalBasis basis;
  Points tool;
  State start;
  ContactPatch::Blocks springs;
  Eigen::VectorXd reduced_anchor = Eigen::VectorXd::Zero(10), reduced_velocity = Eigen::VectorXd::Zero(10);
  std::unique_ptr<ContactPatch> patch;
  ContactPatch::Step step() const {
    ContactPatch::Step s;
    s.tool_forces = &tool;
    s.springs = &springs;
    s.start = &start;
    s.inertia = 1e4;  // a step of 10 ms: the inertia terms weigh with the rest
    s.carry = 1e-2;
    s.reduced_anchor = &reduced_anchor;
    s.reduced_velocity = &reduced_velocity;
    return s;
  }
  Coupled() {
    Workspace ws(model, 2);
    ModalBasisSettings settings;
    settings.size = 10;
    basis = build_modal_basis(model, settings, ws);
    // a tool pushing the top down near x = 8 spacings, and its springs (the full implicit solver's linearisation)
    // toward where the step began
    tool = Points::Zero(3, model.n_points);
    springs = ContactPatch::Blocks::Zero(9, model.n_points);
    start.u = Points::Zero(3, model.n_points);
    start.velocity = Points::Zero(3, model.n_points);  // (the patch takes its points' velocity from q')
    reduced_anchor(0) = 1e-5;
    reduced_velocity(0) = 1e-3;  // the patch's points start moving with the reduced model
    for (const index_t i : pressed_points(model)) {
      tool(1, i) = -0.02;
      Mat3 S = Mat3::Zero();
      S(1, 1) = 50;
      Eigen::Map<Mat3>(springs.col(i).data()) = S;
      start.u(1, i) = -1e-4;
    }
    patch = std::make_unique<ContactPatch>(model, basis.U, 2, 2);
    EXPECT_TRUE(patch->begin_step(model, step()));
  }
  double energy(const Eigen::VectorXd& q, Eigen::VectorXd* gradient = nullptr) {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(q.size());
    double e = 0;
    EXPECT_TRUE(patch->evaluate(q, e, g)) << patch->failure();
    if (gradient) *gradient = g;
    return e;
  }
};

TEST(ContactPatch, TheCoupledGradientIsTheEnergysDerivativeAndTheHessianItsOwn) {
  // Pi(q, v) with the patch's points v as unknowns beside q: along a step (dq, dv) of the kind Newton takes, the
  // energy's slope is g_q . dq + g_v . dv, and the change of g_q is H_qq dq + H_qv dv = S dq - H_qv H_vv^-1 g_v
  // (S the condensed Hessian), both from finite differences
  Coupled c;
  EXPECT_GT(c.patch->free_points(), 0);
  EXPECT_GT(c.patch->patch_points(), c.patch->free_points());
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  Eigen::VectorXd q = Eigen::VectorXd::NullaryExpr(10, [&](Eigen::Index) { return 2e-4 * normal(rng); });
  const Eigen::VectorXd d = Eigen::VectorXd::NullaryExpr(10, [&](Eigen::Index) { return normal(rng); }).normalized();
  Eigen::VectorXd g;
  c.energy(q, &g);
  EXPECT_GT(c.patch->residual(), 0);  // v where its momentum carries it is not at its optimum
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(10, 10);
  c.patch->add_hessian(H);
  Eigen::VectorXd condensed = Eigen::VectorXd::Zero(10);
  c.patch->condense(condensed);
  const double own_slope = c.patch->begin_move(d);
  const double h = 1e-6;
  Eigen::VectorXd g_plus, g_minus;
  c.patch->move(h);
  const double e_plus = c.energy(q + h * d, &g_plus);
  c.patch->move(-h);
  const double e_minus = c.energy(q - h * d, &g_minus);
  const double slope = (e_plus - e_minus) / (2 * h);
  EXPECT_NEAR(g.dot(d) + own_slope, slope, 1e-5 * std::abs(slope) + 1e-12)
      << "g_q.dq " << g.dot(d) << " g_v.dv " << own_slope << " fd " << slope;
  EXPECT_GT(std::abs(own_slope), 1e-3 * std::abs(slope));
  // the Hessian: its patch part is the positive semi-definite part of the patch's tangent (measured 0.27% from the
  // gradient's finite differences here); a Hessian of a wrong sign or a missing part is off by far more
  const Eigen::VectorXd curvature = (g_plus - g_minus) / (2 * h), expected = H * d + condensed;
  EXPECT_LT((expected - curvature).norm(), 1e-2 * curvature.norm()) << expected.transpose() << "\n"
                                                                    << curvature.transpose();
  // where there is nothing to correct (no tool, no springs) the patch is not made
  ContactPatch none(c.model, c.basis.U, 2, 1);
  const Points no_forces = Points::Zero(3, c.model.n_points);
  const ContactPatch::Blocks no_springs = ContactPatch::Blocks::Zero(9, c.model.n_points);
  ContactPatch::Step nothing = c.step();
  nothing.tool_forces = &no_forces;
  nothing.springs = &no_springs;
  EXPECT_FALSE(none.begin_step(c.model, nothing));
  EXPECT_EQ(none.patch_points(), 0);
}

TEST(ContactPatch, StaysWhileItsCorrectionMovesOnAfterTheToolLeavesThenGoes) {
  // dropped at once, the indentation sprang back into a probe that came back (a stiff cantilever diverged)
  Coupled c;
  const Points no_forces = Points::Zero(3, c.model.n_points);
  const ContactPatch::Blocks no_springs = ContactPatch::Blocks::Zero(9, c.model.n_points);
  ContactPatch::Step left = c.step();
  left.tool_forces = &no_forces;
  left.springs = &no_springs;
  const index_t free = c.patch->free_points();
  for (int k = 0; k < ContactPatch::release_steps; ++k) {
    ASSERT_TRUE(c.patch->begin_step(c.model, left)) << k;
    EXPECT_EQ(c.patch->free_points(), free);
  }
  EXPECT_FALSE(c.patch->begin_step(c.model, left));
  EXPECT_EQ(c.patch->free_points(), 0);
  // and a tool that comes back gets a patch again
  EXPECT_TRUE(c.patch->begin_step(c.model, c.step()));
  EXPECT_EQ(c.patch->free_points(), free);
  EXPECT_EQ(c.patch->rebuilds(), 2);
}

// a tool's forces and springs on the top points near x = 8 spacings, as a probe gives them (DynamicForces)
class PushOnTop final : public DynamicForces {
 public:
  explicit PushOnTop(std::vector<index_t> points) : points_(std::move(points)) {}
  void add(const Model&, const State&, Points& f) override {
    for (const index_t i : points_) f(1, i) -= 0.005;
  }
  bool add_stiffness(const Model&, const State&, Eigen::Matrix<double, 9, Eigen::Dynamic>& springs) override {
    for (const index_t i : points_) springs(4, i) += 50;  // (y, y)
    return true;
  }

 private:
  std::vector<index_t> points_;
};

// implicit steps of 1 ms of a reduced model of 10 vectors, the patch two rings wide; `budget`: Newton iterations a
// step (0: converged)
SolverSpec pushed_spec(int budget) {
  SolverSpec spec;
  spec.kind = SolverKind::IMPLICIT;
  spec.dt = 1e-3;
  spec.iteration_budget = budget;
  spec.reduction.modes = 10;
  spec.reduction.contact_rings = 2;
  return spec;
}

TEST(ContactPatch, AReducedStepWithAToolWritesThePatchInFullAndItsVelocity) {
  // the solver's side of the coupling, a few steps (quick under the sanitizers, where a probe's press is not)
  const Model model = cantilever();
  const SolverSpec spec = pushed_spec(0);
  Workspace ws(model, 2);
  ReducedSolver solver(model, spec, ws);
  State state = State::at_rest(model);
  PushOnTop push(pressed_points(model));
  Points before = state.u;
  int iterations = 0;
  for (int k = 0; k < 20; ++k) {
    before = state.u;
    const StepReport report = solver.step(model, state, ws, &push);
    ASSERT_NE(report.status, StepStatus::FAILED) << report.failure;
    EXPECT_FALSE(solver.displacement_unpublished()) << "a tool reads the displacement: written at every step";
    iterations += report.iterations;
  }
  // the velocity where something reads it: the reduced model's, and the patch's own on its points; u was written
  const Points written = state.u;
  EXPECT_TRUE(solver.unpublished());
  solver.publish(state, ws);
  EXPECT_EQ(state.u, written);
  // one Newton on q and the patch's points converges as Newton does: two or three iterations a step (a Schur
  // complement made with the assembled tangent's factor alone, whose hourglass part is a bound, halved the
  // residual at each: ten a step on the stiff beam)
  EXPECT_LE(iterations, 3 * 20);
  ASSERT_NE(solver.contact_patch(), nullptr);
  EXPECT_GT(solver.contact_patch()->free_points(), 0);
  EXPECT_TRUE(state.u.allFinite());
  for (const index_t i : pressed_points(model)) {
    EXPECT_LT(state.u(1, i), 0.0) << "pushed down at " << i;
    // the patch's points carry their own velocity: the step's motion
    EXPECT_LT((state.velocity.col(i) - (state.u.col(i) - before.col(i)) / spec.dt).norm(),
              1e-9 * (1 + state.velocity.col(i).norm()));
  }
}

// a tool whose force is not a number on one point
class NotANumber final : public DynamicForces {
 public:
  explicit NotANumber(index_t point) : point_(point) {}
  void add(const Model&, const State&, Points& f) override { f(1, point_) = NAN; }

 private:
  index_t point_;
};

TEST(ContactPatch, AToolsForceThatIsNotANumberFailsTheStepByName) {
  const Model model = cantilever();
  Workspace ws(model, 1);
  ReducedSolver solver(model, pushed_spec(0), ws);
  State state = State::at_rest(model);
  NotANumber tool(pressed_points(model).front());
  const StepReport report = solver.step(model, state, ws, &tool);
  EXPECT_EQ(report.status, StepStatus::FAILED);
  EXPECT_NE(report.failure.find("not finite"), std::string::npos) << report.failure;
  EXPECT_TRUE(state.u.allFinite());
}

TEST(ContactPatch, OneNewtonIterationAStepCarriesThePatchAlongAndStaysWithConvergedSteps) {
  // real time's iteration budget: the step's one Newton iteration moves the patch's points with q (ReducedCoupling::
  // move), so a step that stops there is close to a converged one
  const Model model = cantilever();
  const auto run = [&](int budget) {
    Workspace ws(model, 2);
    ReducedSolver solver(model, pushed_spec(budget), ws);
    State state = State::at_rest(model);
    PushOnTop push(pressed_points(model));
    for (int k = 0; k < 20; ++k) EXPECT_NE(solver.step(model, state, ws, &push).status, StepStatus::FAILED);
    return state.u;
  };
  const Points converged = run(0), one = run(1);
  double largest = 0, apart = 0;
  for (const index_t i : pressed_points(model)) {
    largest = std::max(largest, converged.col(i).norm());
    apart = std::max(apart, (one.col(i) - converged.col(i)).norm());
  }
  EXPECT_GT(largest, 0.0);
  EXPECT_LT(apart, 0.01 * largest) << "pressed points: " << largest << " m, one iteration a step off by " << apart;
}

struct Press {
  Vec3 felt;  // the force the device rendered at the end, N
  double tip = 0, probe_y = 0, seconds = 0;
  long long steps = 0, rebuilds = 0, iterations = 0;
  index_t patch_points = 0;
};

// a probe 6 mm in radius pressed into the seed's cantilever from above its middle: down 2 R + 4 mm over 0.5 s,
// held for 0.3 s, implicit steps of 1 ms
Press press(const std::string& reduction) {
  const std::string text = test::cantilever_scene("implicit") + reduction +
                           "[probe]\nradius = 0.006\nkeyframes = [[0.0, 0.0, 0.0, 0.0], [0.5, 0.0, -0.016, 0.0], "
                           "[0.8, 0.0, -0.016, 0.0]]\n[device]\nkind = \"virtual\"\n";
  SceneSession s = open_scene(parse_scene(text), {2, 0, true, {}});
  s.interactive.real_time = false;
  s.interactive.duration = 0.8;
  s.interactive.log = true;
  const auto start = std::chrono::steady_clock::now();
  const InteractiveResult r = run_interactive(*s.simulation, *s.device, s.interactive);
  Press p;
  p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_FALSE(s.simulation->diagnostics().failed) << s.simulation->diagnostics().failure;
  p.felt = r.log.empty() ? Vec3::Constant(NAN) : r.log.back().force;
  p.tip = test::cantilever_tip_deflection(s.simulation->model(), s.simulation->state().u);
  p.probe_y = r.tool.position.y();
  p.steps = r.simulation_steps;
  const RunSummary summary = s.simulation->summary();
  p.rebuilds = summary.reduction.contact_patches;
  p.iterations = summary.iterations;
  p.patch_points = static_cast<index_t>(summary.reduction.contact_points);
  return p;
}

TEST(ContactPatch, AProbePressingAReducedCantileverFeelsTheFullModelsForceAndBendsItAsFar) {
  const Press full = press("");
  const Press reduced = press("[reduction]\nmodes = 20\ncache = \"none\"\n");
  std::printf("full: felt %.6g N, tip %.6g m, probe y %.6g m, %.3g s\n", full.felt.y(), full.tip, full.probe_y,
              full.seconds);
  std::printf("reduced: felt %.6g N, tip %.6g m, probe y %.6g m, %.3g s, patch %d points, %lld rebuilds, %lld its\n",
              reduced.felt.y(), reduced.tip, reduced.probe_y, reduced.seconds, static_cast<int>(reduced.patch_points),
              reduced.rebuilds, reduced.iterations);
  ASSERT_GT(full.felt.y(), 0.0) << "the probe presses";
  EXPECT_NEAR(reduced.felt.y(), full.felt.y(), 0.03 * full.felt.y());
  EXPECT_NEAR(reduced.tip, full.tip, 0.03 * std::abs(full.tip));
  EXPECT_NEAR(reduced.probe_y, full.probe_y, 2e-4);
  EXPECT_GT(reduced.patch_points, 0);
}

}  // namespace
}  // namespace pointhaptics
