// Tests for io/result_json: the keys of design.md's contract.
#include <pointhaptics/io/result_json.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace pointhaptics {
namespace {

TEST(ResultJson, HasEveryContractKeyWithOneEntryPerPoint) {
  Model model = build_model(sample_box(Vec3::Zero(), Vec3(0.04, 0.02, 0.02), 0.01), MaterialParams{}, KernelParams{});
  FixedGroup g;
  g.points = {0, 1};
  model.fixed[0] = model.fixed[1] = 1;
  model.fixed_groups.push_back(g);
  State state = State::at_rest(model);
  state.u.col(3) = Vec3(1e-3, -2e-3, 3e-3);
  RunSummary s;
  s.solver_kind = "explicit";
  s.converged = true;
  s.steps = 10;
  s.reactions = {Vec3(0, 0.5, 0)};
  const auto doc = nlohmann::json::parse(result_json(model, state, s));
  for (const char* key : {"reference", "displacement", "fixed", "active"}) {
    ASSERT_TRUE(doc["points"].contains(key)) << key;
    EXPECT_EQ(doc["points"][key].size(), static_cast<size_t>(model.n_points)) << key;
  }
  for (const char* key : {"kind", "converged", "iterations", "residual", "steps"})
    EXPECT_TRUE(doc["solver"].contains(key)) << key;
  for (const char* key : {"strain", "kinetic"}) EXPECT_TRUE(doc["energy"].contains(key)) << key;
  for (const char* key : {"wall_s", "step_ms_mean", "steps_per_s"}) EXPECT_TRUE(doc["timing"].contains(key)) << key;
  for (const char* key : {"active_set_s", "tools_s", "solve_s"})
    EXPECT_TRUE(doc["timing"]["stages"].contains(key)) << key;
  for (const char* key : {"ticks", "rate_hz", "period_p99_us", "max_force_n"})
    EXPECT_TRUE(doc["haptic"].contains(key)) << key;
  for (const char* key : {"selected", "selection_ms", "enabled", "band_count", "band_selected", "selections", "frozen"})
    EXPECT_TRUE(doc["lod"].contains(key)) << key;
  EXPECT_EQ(doc["points"]["displacement"][3][1].get<double>(), -2e-3);
  EXPECT_EQ(doc["points"]["fixed"][1].get<bool>(), true);
  EXPECT_EQ(doc["points"]["fixed"][2].get<bool>(), false);
  ASSERT_EQ(doc["constraints"].size(), 1u);
  EXPECT_EQ(doc["constraints"][0]["points"].get<int>(), 2);
  EXPECT_EQ(doc["constraints"][0]["reaction"][1].get<double>(), 0.5);
  EXPECT_EQ(doc["solver"]["kind"], "explicit");
}

}  // namespace
}  // namespace pointhaptics
