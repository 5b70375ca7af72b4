// Tests for scene_session: a scene becomes its simulation, levels of detail, device and interactive options
// in one place, with the same defaults for every front end; bad scenes are named errors.
#include <pointhaptics/session/scene_session.hpp>

#include <pointhaptics/haptics/devices/virtual_device.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/world/simulation.hpp>

#include "support/test_scenes.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

const std::string probe_and_lod = R"(
[probe]
radius = 0.004
keyframes = [[0.0, 0.0, 0.0, 0.0], [0.5, 0.0, -0.01, 0.0]]
[lod]
k1 = 1.0
k2 = 1.5
contact = [0.075, 0.03, 0.015]
)";

TEST(SceneSession, AProbeSceneGetsItsDeviceOptionsAndLevelsOfDetail) {
  const SceneSession s = open_scene(parse_scene(test::cantilever_scene() + probe_and_lod), {1, 0, true, {}});
  ASSERT_TRUE(s.simulation);
  EXPECT_TRUE(s.simulation->lod_enabled());
  EXPECT_LT(s.simulation->simulated_model().n_points, s.simulation->model().n_points);
  ASSERT_TRUE(s.device);
  EXPECT_NE(dynamic_cast<VirtualDevice*>(s.device.get()), nullptr);
  EXPECT_DOUBLE_EQ(s.interactive.probe.radius, 0.004);
  // the device origin defaults to two probe radii above the centre of the object's top
  EXPECT_LE((s.interactive.mapping.origin - Vec3(0.075, 0.03 + 2 * 0.004, 0.015)).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(s.interactive.duration, 2.0);
  EXPECT_GE(s.setup_seconds, 0.0);
  // a front end with its own device (the viewer, Python) gets the same options without one
  const SceneSession without = open_scene(parse_scene(test::cantilever_scene() + probe_and_lod), {1, 0, false, {}});
  EXPECT_FALSE(without.device);
  EXPECT_EQ(without.interactive.mapping.origin, s.interactive.mapping.origin);
  EXPECT_EQ(without.simulation->simulated_model().n_points, s.simulation->simulated_model().n_points);
}

TEST(SceneSession, APlainSceneHasNeitherDeviceNorLevelsOfDetail) {
  const SceneSession s = open_scene(parse_scene(test::cantilever_scene()), {1, 0, true, {}});
  EXPECT_FALSE(s.device);
  EXPECT_FALSE(s.simulation->lod_enabled());
  EXPECT_EQ(s.simulation->solver().kind, SolverKind::EXPLICIT);
  EXPECT_EQ(s.scene.solver.duration, 2.0);
}

// A static solve where nothing pushes but round-off (scenes/indentation.toml run as it is: its sphere only
// touches the top face; `fit` presses it) is at rest, and says so at once: its residual is measured against the
// model's force floor (solvers/reactions.hpp), not against the round-off, which no iterate lowers (it took
// 700 Newton iterations and 14 load cutbacks to report "not converged")
TEST(SceneSession, AStaticSolveWithNothingPushingConvergesAtRest) {
  Scene scene = read_scene_file(PH_SCENES "/indentation.toml");
  scene.object.spacing = 0.005;  // coarser than the file's: the same touch, faster
  scene.refine.at(0).spacing = 0.0025;
  const SceneSession s = open_scene(scene, {1, 0, true, {}});
  s.simulation->run(0);
  const RunSummary summary = s.simulation->summary();
  EXPECT_TRUE(summary.converged) << summary.failure;
  EXPECT_LE(summary.iterations, 10);
  EXPECT_LT(summary.residual, 1e-6);
  EXPECT_LT(s.simulation->state().u.cwiseAbs().maxCoeff(), 1e-9) << "at rest, to round-off";
}

TEST(SceneSession, BadScenesAreNamedErrors) {
  EXPECT_THROW(open_scene_file("/nonexistent/scene.toml"), Error);
  // a model beyond the memory allowed is refused before it is built
  try {
    open_scene(parse_scene(test::cantilever_scene()), {1, 1e3, true, {}});
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("memory"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pointhaptics
