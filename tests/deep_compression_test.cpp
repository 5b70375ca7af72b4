// Deep compression (issue 17, item 2): a soft block bonded between two plates and compressed statically, a
// flat punch pressed 5 mm into soft tissue, and a probe pushed to half a soft block's thickness. St.
// Venant-Kirchhoff collapses and inverts, which must be reported instead of "converged"; neo-Hookean holds.
#include <pointhaptics/session/interactive.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/session/scene_session.hpp>

#include <gtest/gtest.h>
#include <fmt/format.h>

namespace pointhaptics {
namespace {

// a 5 cm cube (E = 2e4 Pa, nu = 0.4) between a held bottom plate and a top plate moved down by `strain`,
// sampled at `spacing`
RunSummary compress(const std::string& model, double strain, double spacing = 0.005) {
  const std::string text = fmt::format(R"(
[object]
shape = "box"
size = [0.05, 0.05, 0.05]
spacing = {}
[material]
model = "{}"
young = 2e4
poisson = 0.4
[[fixed]]
box = {{ min = [-1.0, -1.0, -1.0], max = [1.0, 0.0, 1.0] }}
[[fixed]]
box = {{ min = [-1.0, 0.05, -1.0], max = [1.0, 1.0, 1.0] }}
displacement = [0.0, {}, 0.0]
[solver]
kind = "static"
)",
                                       spacing, model, -0.05 * strain);
  SceneSession session = open_scene(parse_scene(text, "compression.toml"));
  session.simulation->step();
  return session.simulation->summary();
}

TEST(DeepCompression, StVenantKirchhoffCollapseIsReportedNotConverged) {
  // 10%: fine; 20%: the issue's measurement, a collapsed and inverted state where the plate pulls the block
  const RunSummary mild = compress("svk", 0.1);
  EXPECT_TRUE(mild.converged) << mild.failure;
  EXPECT_EQ(mild.inverted, 0);
  const RunSummary deep = compress("svk", 0.2);
  EXPECT_FALSE(deep.converged);
  EXPECT_GT(deep.inverted, 0);
  EXPECT_NE(deep.failure.find("inverted"), std::string::npos) << deep.failure;
  EXPECT_GT(deep.reactions[1].y(), 0.0);  // the plate pulls: against its motion
  ASSERT_EQ(deep.collapsed.size(), 1u);
  EXPECT_EQ(deep.collapsed[0], "fixed[1]");
}

TEST(DeepCompression, NeoHookeanHoldsAndStiffensToHalfTheHeight) {
  double previous = 0;
  for (const double strain : {0.1, 0.3, 0.5}) {
    const RunSummary s = compress("neo_hookean", strain, 0.00625);  // 9 points an edge: the sanitizer builds run it too
    ASSERT_TRUE(s.converged) << strain << ": " << s.failure;
    EXPECT_EQ(s.inverted, 0);
    EXPECT_TRUE(s.collapsed.empty());
    const double force = -s.reactions[1].y();  // pushing the block down
    // the secant stiffness force / strain grows: it stiffens under compression
    EXPECT_GT(force / strain, previous) << "strain " << strain;
    previous = force / strain;
  }
}

TEST(DeepCompression, AFlatPunchPressedFiveMillimetresSolvesWithNeoHookean) {
  // the issue's punch: a 0.1 x 0.05 x 0.1 m block, E = 1e4 Pa, nu = 0.45, bottom held, the top face's points
  // within 10 mm of the centre pushed 5 mm down (scenes/punch.toml)
  SceneSession session = open_scene_file(PH_SCENES "/punch.toml");
  session.simulation->step();
  const RunSummary s = session.simulation->summary();
  EXPECT_TRUE(s.converged) << s.failure;
  EXPECT_EQ(s.inverted, 0);
  const double force = -s.reactions[1].y();
  EXPECT_GT(force, 0.5);
  EXPECT_LT(force, 5.0);
}

TEST(DeepCompression, AProbePushedToHalfASoftBlocksThicknessNeitherInvertsNorMakesNaN) {
  auto press = [](const std::string& model) {
    const std::string text = fmt::format(R"(
[object]
shape = "box"
size = [0.05, 0.04, 0.05]
origin = [-0.025, 0.0, -0.025]
spacing = 0.005
[material]
model = "{}"
young = 1e4
poisson = 0.45
damping = 20.0
[[fixed]]
box = {{ min = [-1.0, -1.0, -1.0], max = [1.0, 0.0, 1.0] }}
[solver]
kind = "explicit"
dt = 1e-3
duration = 0.6
[probe]
radius = 0.01
mode = "push"
stiffness = 500.0
# the probe starts 10 mm above the top (two radii above it, centre): its lowest point reaches half the thickness
keyframes = [[0.0, 0.0, 0.0, 0.0], [0.45, 0.0, -0.03, 0.0], [0.6, 0.0, -0.03, 0.0]]
[device]
kind = "virtual"
specs = "custom"
max_force = 100.0
max_stiffness = 1e5
workspace_radius = 0.2
)",
                                         model);
    SessionOptions options;
    options.make_device = true;
    SceneSession session = open_scene(parse_scene(text, "press.toml"), options);
    session.interactive.real_time = false;
    run_interactive(*session.simulation, *session.device, session.interactive);
    return session.simulation->summary();
  };
  const RunSummary nh = press("neo_hookean");
  EXPECT_TRUE(nh.converged) << nh.failure;
  EXPECT_EQ(nh.inverted, 0);
  EXPECT_EQ(nh.inverted_steps, 0);
  EXPECT_TRUE(std::isfinite(nh.strain_energy));
  // St. Venant-Kirchhoff under the same probe: inverted, and said so
  const RunSummary svk = press("svk");
  EXPECT_GT(svk.inverted_steps, 0);
}

}  // namespace
}  // namespace pointhaptics
