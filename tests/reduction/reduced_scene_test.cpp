// Tests for [reduction] in a scene: the seed's cantilever (St. Venant-Kirchhoff, tip traction) solved statically and
// stepped implicitly in a reduced basis agrees with the full point model; what a reduced model does not do yet is
// refused by name at the table's line.
#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/inversion.hpp>
#include <pointhaptics/pointhaptics.hpp>
#include <pointhaptics/reduction/reduced_solver.hpp>
#include <pointhaptics/world/model_simulation.hpp>

#include "support/test_scenes.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace pointhaptics {
namespace {

double tip_deflection(const Simulation& sim) { return test::cantilever_tip_deflection(sim.model(), sim.state().u); }

std::string reduced(const std::string& solver, const std::string& more = "") {
  // nothing kept between runs: each test makes its basis (basis_cache_test.cpp tests the cache)
  return test::cantilever_scene(solver) + "[reduction]\nmodes = 20\ncache = \"none\"\n" + more;
}

TEST(ReducedScene, StaticCantileverSagsAsTheFullModel) {
  // 0.01 N and 0.2 N at the tip (1.1% and 21% of the length). Measured at r = 20: 0.00165729 and 0.0315573 m against
  // the full model's 0.00165794 and 0.0317417 m (-0.04%, -0.58%); at r = 12 the large one was 2.3% short
  for (const char* total : {"-0.01", "-0.2"}) {
    std::string full_text = test::cantilever_scene("static"), reduced_text = reduced("static");
    for (std::string* text : {&full_text, &reduced_text})
      text->replace(text->find("total = [0.0, -0.01, 0.0]"), std::string("total = [0.0, -0.01, 0.0]").size(),
                    fmt::format("total = [0.0, {}, 0.0]", total));
    Scene full_scene = parse_scene(full_text), reduced_scene = parse_scene(reduced_text);
    EXPECT_EQ(reduced_scene.solver.reduction.modes, 20);
    Simulation full(build_scene_model(full_scene), full_scene.solver, 2);
    full.run(full_scene.solver.duration);
    Simulation sim(build_scene_model(reduced_scene), reduced_scene.solver, 2);
    sim.run(reduced_scene.solver.duration);
    ASSERT_TRUE(sim.summary().converged) << sim.summary().failure;
    EXPECT_NEAR(tip_deflection(sim), tip_deflection(full), 0.02 * tip_deflection(full)) << "total " << total;
  }
}

TEST(ReducedScene, ABasisMadeOnACoarserSamplingIsStifferThanTheFullModelBySomePercent) {
  // at 3.75 mm (9 points across), the basis made at 7.5 mm (5 across)
  const auto finer = [](std::string text) {
    text.replace(text.find("spacing = 0.0075"), std::string("spacing = 0.0075").size(), "spacing = 0.00375");
    return text;
  };
  Scene full_scene = parse_scene(finer(test::cantilever_scene("static")));
  Simulation full(build_scene_model(full_scene), full_scene.solver, 2);
  full.run(full_scene.solver.duration);
  Scene scene = parse_scene(finer(reduced("static", "basis_spacing = 0.0075\n")));
  EXPECT_EQ(scene.solver.reduction.basis_spacing, 0.0075);
  Simulation sim(build_scene_model(scene), scene.solver, 2);
  sim.run(scene.solver.duration);
  ASSERT_TRUE(sim.summary().converged) << sim.summary().failure;
  // a subspace of the full model's: its compliance under the load is less (the Ritz bound), by 5.6% here (measured
  // 0.00157999 against 0.00167433 m). The coarse sampling has only 5 points across the beam: the 10k-point beam's
  // basis at 7 across falls 1.8-2.1% short (docs/reduction.md)
  EXPECT_LT(tip_deflection(sim), tip_deflection(full));
  EXPECT_GT(tip_deflection(sim), 0.94 * tip_deflection(full));
  // not coarser than the object's own spacing: named
  Scene too_fine = parse_scene(reduced("static", "basis_spacing = 0.005\n"));
  EXPECT_THROW(Simulation(build_scene_model(too_fine), too_fine.solver, 2), Error);
}

TEST(ReducedScene, ImplicitStepsSettleOnTheFullModelsSag) {
  Scene full_scene = parse_scene(test::cantilever_scene("static"));
  Simulation full(build_scene_model(full_scene), full_scene.solver, 2);
  full.run(full_scene.solver.duration);
  Scene scene = parse_scene(reduced("implicit"));
  Simulation sim(build_scene_model(scene), scene.solver, 2);
  sim.run(1.0);
  ASSERT_TRUE(sim.summary().converged) << sim.summary().failure;
  EXPECT_NEAR(sim.state().time, 1.0, 1e-9);
  // the set-up is reported, in the result JSON too
  const RunSummary summary = sim.summary();
  EXPECT_EQ(summary.reduction.modes, 20);
  EXPECT_GT(summary.reduction.linear_modes, 0);
  EXPECT_GT(summary.reduction.derivatives, 0);
  EXPECT_EQ(summary.reduction.load_vectors, 1);
  EXPECT_GT(summary.reduction.setup_s, 0);
  EXPECT_GT(summary.reduction.tables_bytes, 0);
  const auto json = nlohmann::json::parse(result_json(sim.model(), sim.state(), summary));
  EXPECT_EQ(json.at("reduction").at("modes").get<int>(), 20);
  EXPECT_GT(json.at("reduction").at("setup_s").get<double>(), 0);
  EXPECT_FALSE(nlohmann::json::parse(result_json(full.model(), full.state(), full.summary())).contains("reduction"));
  EXPECT_NEAR(tip_deflection(sim), tip_deflection(full), 0.02 * tip_deflection(full));
}

TEST(ReducedScene, TheGradientBoundHoldsAtEveryPointSoNoInvertedPointIsMissed) {
  // count_inverted answers 0 without a stencil pass while |q| max_p c_p < 1: that must bound every point's |G_p|
  for (const char* total : {"-0.01", "-0.2"}) {
    std::string text = reduced("static");
    text.replace(text.find("total = [0.0, -0.01, 0.0]"), std::string("total = [0.0, -0.01, 0.0]").size(),
                 fmt::format("total = [0.0, {}, 0.0]", total));
    Scene scene = parse_scene(text);
    ModelSimulation sim(build_scene_model(scene), scene.solver, 2);
    sim.step();
    const Model& model = sim.model();
    const Points& u = sim.state().u;
    double q2 = 0;  // |q|^2 = u^T M u: the basis is mass-orthonormal
    for (index_t i = 0; i < model.n_points; ++i) q2 += model.mass[i] * u.col(i).squaredNorm();
    auto& solver = dynamic_cast<ReducedSolver&>(sim.solver_impl());
    double largest = 0;
    for (index_t p = 0; p < model.stencil_end(); ++p)
      largest = std::max(largest, displacement_gradient(model, u, p).operatorNorm());
    EXPECT_GT(largest, 0);
    EXPECT_LE(largest, std::sqrt(q2) * solver.gradient_bound() * (1 + 1e-9)) << "total " << total;
    // and the count it gives is the state's
    EXPECT_EQ(solver.count_inverted(model, sim.state(), sim.workspace()), count_inverted(model, u, sim.workspace()));
  }
}

TEST(ReducedScene, TheStateIsWrittenWhenReadAndReadsTheSameAsWrittenAtEveryStep) {
  // a step leaves u = U q and v = U q' unwritten (writing them cost several reduced steps); state() writes them
  Scene scene = parse_scene(reduced("implicit"));
  ModelSimulation lazy(build_scene_model(scene), scene.solver, 2);
  ModelSimulation eager(build_scene_model(scene), scene.solver, 2);
  for (int k = 0; k < 50; ++k) {
    lazy.step();
    EXPECT_TRUE(lazy.solver_impl().unpublished());
    eager.step();
    (void)eager.state();  // read at every step: written at every step
  }
  const Points held_before = lazy.state().u;  // (read: written now)
  EXPECT_FALSE(lazy.solver_impl().unpublished());
  EXPECT_EQ(held_before, eager.state().u);
  EXPECT_EQ(lazy.state().velocity, eager.state().velocity);
  EXPECT_GT(held_before.cwiseAbs().maxCoeff(), 1e-5) << "it moved";
  // Simulation::run() writes it at its end, step() at every step: a reference held across them reads it whole
  Simulation sim(build_scene_model(scene), scene.solver, 2);
  const State& held = sim.state();
  sim.run(0.05);
  EXPECT_EQ(held.u, eager.state().u);
  sim.step();
  EXPECT_NE(held.u, eager.state().u);
  eager.step();
  EXPECT_EQ(held.u, eager.state().u);
}

TEST(ReducedScene, AStateSetFromOutsideIsWhereTheNextStepsContinueFrom) {
  // it was overwritten by the solver's own coordinates at the next step
  Scene scene = parse_scene(reduced("implicit"));
  Simulation first(build_scene_model(scene), scene.solver, 2), second(build_scene_model(scene), scene.solver, 2);
  first.run(0.05);
  second.set_state(first.state());
  first.run(0.02);
  second.run(0.02);
  const double size = first.state().u.cwiseAbs().maxCoeff();
  EXPECT_GT(size, 1e-5);
  EXPECT_LT((second.state().u - first.state().u).cwiseAbs().maxCoeff(), 1e-9 * size);
  EXPECT_LT((second.state().velocity - first.state().velocity).cwiseAbs().maxCoeff(),
            1e-9 * first.state().velocity.cwiseAbs().maxCoeff());
}

TEST(ReducedScene, WhatIsNotReducedYetIsANamedError) {
  const auto error = [](const std::string& text) {
    try {
      parse_scene(text, "reduced.toml");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error(reduced("explicit")).find("reduction: needs solver.kind"), std::string::npos);
  EXPECT_NE(error(test::cantilever_scene("static") + "[reduction]\n").find("modes"), std::string::npos);
  EXPECT_NE(error(reduced("static", "basis = \"snapshots\"\n")).find("not built yet"), std::string::npos);
  EXPECT_NE(error(reduced("static", "forces = \"hyper\"\n")).find("not built yet"), std::string::npos);
  EXPECT_NE(error(reduced("static", "modes_ = 3\n")).find("modes_"), std::string::npos);
  std::string neo = reduced("static");
  neo.replace(neo.find("[material]\n"), 11, "[material]\nmodel = \"neo_hookean\"\n");
  EXPECT_NE(error(neo).find("svk"), std::string::npos);
  // a device's probe pushing is coupled (contact_patch_test.cpp); grabbing is not yet
  const std::string probe =
      reduced("implicit") +
      "[probe]\nradius = 0.005\nkeyframes = [[0.0, 0.1, 0.05, 0.015]]\n[device]\nkind = \"virtual\"\n";
  EXPECT_EQ(error(probe), "no error");
  std::string grab = probe;
  grab.replace(grab.find("radius = 0.005"), 14, "radius = 0.005\nmode = \"grab\"");
  EXPECT_NE(error(grab).find("reduced.toml:"), std::string::npos);
  EXPECT_NE(error(grab).find("grabbing"), std::string::npos) << error(grab);
  EXPECT_NE(error(reduced("implicit", "contact_rings = 0\n")).find("contact_rings"), std::string::npos);
}

}  // namespace
}  // namespace pointhaptics
