// Named tools (issue 47): [[tool]] tables held at a position or moved along keyframes (any number of them), one
// driven by a named [[device]]; read with named errors. A posed tool indents as a held [probe] does; two tools
// pinching a free block under gravity carry its weight by friction in a static solve, or let it slip when the
// pinch is below the weight over 2 mu; two keyframed tools lift a block off a table in implicit dynamics.
#include <pointhaptics/io/result_json.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/session/interactive.hpp>
#include <pointhaptics/session/scene_session.hpp>
#include <pointhaptics/world/simulation.hpp>

#include "support/scene_sessions.hpp"

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <string>

using namespace pointhaptics;

namespace {

constexpr double weight = 0.02 * 0.02 * 0.02 * 1000.0 * 9.81;  // the 2 cm sample's, N

using test::error_of;
using test::two_threads;

const ToolSummary& tool(const RunSummary& s, const std::string& name) {
  for (const auto& [n, t] : s.tools)
    if (n == name) return t;
  throw Error("no tool " + name);
}

// a 2 x 2 x 2 cm sample from the origin (E = 50 kPa, 8 g) under gravity, and `more`
std::string sample(const std::string& solver, const std::string& more) {
  return fmt::format(R"(
[object]
shape = "box"
size = [0.02, 0.02, 0.02]
spacing = 0.0025
[material]
young = 5e4
poisson = 0.3
density = 1000.0
damping = 0.05
[solver]
{}
[[load]]
kind = "gravity"
{}
)",
                     solver, more);
}

// a jaw: a vertical capsule (axis along y) of 5 mm radius, its straight part longer than the sample is high,
// pressing on the face x = 0 (side -1) or x = 0.02 (side +1) `depth` deep, or moved along `keyframes`
std::string jaw(const std::string& name, double mu, const std::string& where, double length = 0.04) {
  return fmt::format(R"(
[[tool]]
name = "{}"
shape = "capsule"
radius = 0.005
length = {}
orientation = [0.7071067811865476, -0.7071067811865476, 0.0, 0.0]
friction = {}
{}
)",
                     name, length, mu, where);
}
std::string pinch(double mu, double depth = 0.001) {
  return jaw("left", mu, fmt::format("position = [{}, 0.01, 0.01]", -0.005 + depth)) +
         jaw("right", mu, fmt::format("position = [{}, 0.01, 0.01]", 0.025 - depth));
}

TEST(Tools, TablesAreReadAndTheirMistakesNamed) {
  const Scene scene = parse_scene(sample("kind = \"static\"", pinch(0.5) + R"(
[[tool]]
name = "finger"
radius = 0.003
keyframes = [[0.0, 0.01, 0.03, 0.01], [0.5, 0.01, 0.021, 0.01]])"));
  ASSERT_EQ(scene.tools.size(), 3u);
  EXPECT_EQ(scene.tools[0].name, "left");
  EXPECT_TRUE(scene.tools[0].probe.capsule);
  EXPECT_DOUBLE_EQ(scene.tools[0].probe.length, 0.04);
  EXPECT_DOUBLE_EQ(scene.tools[1].probe.friction, 0.5);
  EXPECT_DOUBLE_EQ(scene.tools[1].probe.position.x(), 0.024);
  ASSERT_EQ(scene.tools[2].path.size(), 2u);
  EXPECT_DOUBLE_EQ(scene.tools[2].path[1][2], 0.021);
  EXPECT_FALSE(scene.probe.present);

  const std::string device = "\n[[device]]\nname = \"hand\"\n";
  struct Case {
    std::string text, message;
  };
  const std::vector<Case> cases = {
      {"[[tool]]\nradius = 0.003\nposition = [0.0, 0.03, 0.0]", "tool[0].name"},
      {jaw("left", 0, "position = [0.0, 0.03, 0.0]") + jaw("left", 0, "position = [0.0, 0.04, 0.0]"),
       "tool[1].name: \"left\" is already the name of tool[0]"},
      {"[[tool]]\nname = \"a\"\nradius = 0.003", "give one of them, or device"},
      {"[[tool]]\nname = \"a\"\nposition = [0.0, 0.03, 0.0]\nkeyframes = [[0.0, 0.0, 0.03, 0.0]]",
       "give one of them, or device"},
      {"[[tool]]\nname = \"a\"\nmode = \"grab\"\nposition = [0.0, 0.03, 0.0]", "tool[0].mode: only a tool driven"},
      {"[[tool]]\nname = \"a\"\nkeyframes = [[0.5, 0.0, 0.03, 0.0], [0.2, 0.0, 0.03, 0.0]]", "times must increase"},
      {"[[tool]]\nname = \"a\"\ndevice = \"foot\"\nkeyframes = [[0.0, 0.0, 0.03, 0.0]]" + device,
       "tool[0].device: no [[device]] is named \"foot\" (the devices: \"hand\")"},
      {"[[tool]]\nname = \"a\"\ndevice = \"hand\"\nkeyframes = [[0.0, 0.0, 0.03, 0.0]]\n"
       "[[tool]]\nname = \"b\"\ndevice = \"hand\"\nkeyframes = [[0.0, 0.0, 0.03, 0.0]]" +
           device,
       "tool[1].device: \"hand\" already drives tool[0] \"a\" (one tool per device)"},
      {"[[tool]]\nname = \"a\"\nposition = [0.0, 0.03, 0.0]" + device + "[[device]]\nname = \"hand\"\n",
       "device[1].name: \"hand\" is already the name of device[0]"},
      {"[[tool]]\nname = \"a\"\nposition = [0.0, 0.03, 0.0]" + device, "device[0]: \"hand\" drives no tool"},
      {"[[tool]]\nname = \"a\"\ndevice = \"hand\"\nkeyframes = [[0.0, 0.0, 0.03, 0.0]]\n"
       "[[tool]]\nname = \"b\"\ndevice = \"foot\"\nkeyframes = [[0.0, 0.0, 0.03, 0.0]]" +
           device + "[[device]]\nname = \"foot\"\n[lod]\ncontact = [0.01, 0.02, 0.01]",
       "tool \"b\": a second device-driven tool (two hands) is not yet with levels of detail"},
      {"[[tool]]\nname = \"a\"\ndevice = \"hand\"\nkeyframes = [[0.0, 0.0, 0.03, 0.0]]" + device +
           "[probe]\nkeyframes = [[0.0, 0.0, 0.03, 0.0]]",
       "tool[0].device: the scene's [probe] / [device] already make its device-driven tool"},
      {"[[tool]]\nname = \"a\"\nposition = [0.0, 0.03, 0.0]\n[lod]\ncontact = [0.01, 0.02, 0.01]",
       "not yet with levels of detail"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    const std::string message = error_of(sample("kind = \"implicit\"", c.text));
    EXPECT_NE(message.find(c.message), std::string::npos) << message;
    EXPECT_NE(message.find("scene.toml:"), std::string::npos) << message;
  }
}

// a [[tool]] driven by a [[device]] is the scene's probe and device, as [probe] and [device] give them
TEST(Tools, OneDrivenByADeviceIsTheProbeItsTableDescribes) {
  const std::string keys =
      "radius = 0.004\nfriction = 0.3\nkeyframes = [[0.0, 0.01, 0.03, 0.01], [0.5, 0.01, 0.019, 0.01, 1]]\n"
      "origin = [0.0, 0.0, 0.0]\n";
  const Scene named =
      parse_scene(sample("kind = \"implicit\"", "[[tool]]\nname = \"finger\"\ndevice = \"hand\"\n" + keys +
                                                    "[[device]]\nname = \"hand\"\nspecs = \"falcon\"\n"));
  const Scene single =
      parse_scene(sample("kind = \"implicit\"", "[probe]\n" + keys + "[device]\nspecs = \"falcon\"\n"));
  EXPECT_TRUE(named.tools.empty());
  EXPECT_EQ(named.probe_name, "finger");
  ASSERT_TRUE(named.probe.present);
  EXPECT_DOUBLE_EQ(named.probe.radius, single.probe.radius);
  EXPECT_DOUBLE_EQ(named.probe.friction, single.probe.friction);
  EXPECT_EQ(named.probe.keyframes, single.probe.keyframes);
  EXPECT_EQ(named.device.specs, "falcon");
  EXPECT_EQ(named.device.kind, single.device.kind);
}

// a posed tool held 1 mm into a block fixed at its base presses as a [probe] held there does, reported by name in
// the summary and the result JSON's `tools` (beside a [probe]'s, under "probe")
TEST(Tools, APosedToolIndentsAsAHeldProbeAndIsReportedByName) {
  const std::string base = "[[fixed]]\nbox = { min = [-1.0, -1.0, -1.0], max = [1.0, 0.0, 1.0] }\n";
  SceneSession probe = open_scene(
      parse_scene(sample("kind = \"static\"", base + "[probe]\nradius = 0.005\nposition = [0.01, 0.024, 0.01]")),
      two_threads());
  SceneSession named = open_scene(
      parse_scene(sample("kind = \"static\"", base + "[[tool]]\nname = \"finger\"\nradius = 0.005\nposition = [0.01, "
                                                     "0.024, 0.01]\n[[tool]]\nname = \"away\"\nradius = "
                                                     "0.005\nposition = [0.1, 0.1, 0.1]")),
      two_threads());
  probe.simulation->step();
  named.simulation->step();
  const RunSummary a = probe.simulation->summary(), b = named.simulation->summary();
  ASSERT_TRUE(a.converged && b.converged) << a.failure << b.failure;
  ASSERT_TRUE(a.tool.present);
  ASSERT_EQ(b.tools.size(), 2u);
  EXPECT_GT(a.tool.force.y(), 0.01);  // pressing down on the block: the block pushes it up
  EXPECT_LT((tool(b, "finger").force - a.tool.force).norm(), 1e-6 * a.tool.force.norm());
  EXPECT_EQ(tool(b, "away").contacts, 0);
  const nlohmann::json doc =
      nlohmann::json::parse(result_json(named.simulation->model(), named.simulation->state(), b));
  EXPECT_NEAR(doc["tools"]["finger"]["force"][1].get<double>(), tool(b, "finger").force.y(), 1e-12);
  EXPECT_EQ(doc["tools"].size(), 2u);
  const nlohmann::json single =
      nlohmann::json::parse(result_json(probe.simulation->model(), probe.simulation->state(), a));
  EXPECT_NEAR(single["tools"]["probe"]["force"][1].get<double>(), a.tool.force.y(), 1e-12);
  EXPECT_TRUE(single.contains("tool"));
}

// two vertical jaws pinch a free sample 1 mm deep from both sides under gravity (nothing else holds it): in a
// static solve friction carries the weight, half on each jaw, their normal forces equal and opposite; below the
// weight over 2 x the normal force the sample slips and the solve has no equilibrium, above it holds
TEST(Tools, TwoToolsPinchingASampleCarryItsWeightByFrictionOrLetItSlip) {
  const auto solve = [](double mu) {
    SceneSession s =
        open_scene(parse_scene(sample("kind = \"static\"\nmax_iterations = 15", pinch(mu))), two_threads());
    s.simulation->step();
    return s.simulation->summary();
  };
  const RunSummary held = solve(0.5);
  ASSERT_TRUE(held.converged) << held.failure;
  const ToolSummary &left = tool(held, "left"), &right = tool(held, "right");
  EXPECT_NEAR(left.force.y() + right.force.y(), -weight, 0.005 * weight);  // the sample hangs on them
  EXPECT_NEAR(left.force.y(), right.force.y(), 0.005 * weight);
  EXPECT_GT(right.force.x(), 5 * weight);  // pressed apart
  EXPECT_LT((left.force + right.force).cwiseAbs().maxCoeff() - std::abs(left.force.y() + right.force.y()),
            1e-6 * right.force.x());                              // normal forces equal and opposite
  EXPECT_NEAR(left.friction.y(), left.force.y(), 0.01 * weight);  // carried by friction, not by the pressure
  // the threshold: the pinch's normal force N against the weight, mu* = W / (2 N)
  const double threshold = weight / (2 * right.force.x());
  const RunSummary slips = solve(0.95 * threshold);
  EXPECT_FALSE(slips.converged);
  EXPECT_NE(slips.failure.find("no equilibrium"), std::string::npos) << slips.failure;
  const RunSummary holds = solve(1.05 * threshold);
  EXPECT_TRUE(holds.converged) << holds.failure;
  EXPECT_NEAR(tool(holds, "left").force.y() + tool(holds, "right").force.y(), -weight, 0.005 * weight);
}

// two jaws close 1 mm into a sample resting on a table over 0.1 s, lift it 1 cm over 0.2 s and hold it: in
// implicit dynamics friction lifts it off the table (mu = 0.5), or it slips and stays (mu = 0.02)
TEST(Tools, TwoKeyframedToolsLiftASampleOffTheTable) {
  const auto lift = [](double mu) {
    const std::string table =
        "[[obstacle]]\nname = \"table\"\nplane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }\nfriction = "
        "0.5\n";
    const auto path = [](double x0, double x1) {
      return fmt::format("keyframes = [[0.0, {0}, 0.0125, 0.01], [0.1, {1}, 0.0125, 0.01], [0.3, {1}, 0.0225, 0.01]]",
                         x0, x1);
    };
    SceneSession s = open_scene(
        parse_scene(sample("kind = \"implicit\"\ndt = 0.002", table + jaw("left", mu, path(-0.0055, -0.004), 0.016) +
                                                                  jaw("right", mu, path(0.0255, 0.024), 0.016))),
        two_threads());
    s.simulation->run(0.4);
    return std::pair(s.simulation->summary(), Points(s.simulation->state().u));
  };
  const auto [lifted, u] = lift(0.5);
  ASSERT_TRUE(lifted.converged) << lifted.failure;
  EXPECT_NEAR(u.row(1).mean(), 0.01, 0.001);  // carried up with the jaws, less their grip's give
  ASSERT_EQ(lifted.obstacles.size(), 1u);
  EXPECT_EQ(lifted.obstacles[0].second.contacts, 0);  // off the table
  EXPECT_NEAR(tool(lifted, "left").force.y() + tool(lifted, "right").force.y(), -weight, 0.01 * weight);
  const auto [slipped, v] = lift(0.02);
  ASSERT_TRUE(slipped.converged) << slipped.failure;
  EXPECT_LT(v.row(1).mean(), 0.002);  // left on the table
  EXPECT_GT(slipped.obstacles[0].second.contacts, 0);
}

// a grasper: capsule jaws of 5 mm radius and 16 mm (their axes along y), moved along `keyframes` [t, x, y, z, opening]
std::string grasper(const std::string& keyframes, double mu = 0.5) {
  return fmt::format(R"(
[[tool]]
name = "grasper"
shape = "grasper"
radius = 0.005
length = 0.016
orientation = [0.7071067811865476, -0.7071067811865476, 0.0, 0.0]
friction = {}
keyframes = {}
)",
                     mu, keyframes);
}

TEST(Tools, AGrasperIsReadAndItsMistakesNamed) {
  const Scene scene =
      parse_scene(sample("kind = \"implicit\"", grasper("[[0.0, 0.01, 0.0125, 0.01, 0.021], [0.1, 0.01, 0.0125, 0.01, "
                                                        "0.018]]")),
                  "scene.toml");
  ASSERT_EQ(scene.tools.size(), 1u);
  EXPECT_TRUE(scene.tools[0].probe.grasper);
  EXPECT_EQ(scene.tools[0].opening, (std::vector<double>{0.021, 0.018}));
  struct Case {
    std::string text, message;
  };
  const std::vector<Case> cases = {
      {grasper("[[0.0, 0.01, 0.0125, 0.01]]"), "each keyframe is [t, x, y, z, opening]"},
      {grasper("[[0.0, 0.01, 0.0125, 0.01, 2.0]]"), "opening (the 5th value) must lie in [0, 1]"},
      {"[[tool]]\nname = \"g\"\nshape = \"grasper\"\nlength = 0.01\nposition = [0.0, 0.03, 0.0]",
       "needs opening = <m>"},
      {"[[tool]]\nname = \"g\"\nshape = \"grasper\"\nposition = [0.0, 0.03, 0.0]\nopening = 0.01",
       "a grasper needs length > 0"},
      {"[[tool]]\nname = \"g\"\nposition = [0.0, 0.03, 0.0]\nopening = 0.01", "only a grasper has an opening"},
      {"[probe]\nshape = \"grasper\"\nlength = 0.01\nkeyframes = [[0.0, 0.0, 0.0, 0.0]]",
       "a grasper driven by a device needs opening = <m> (its jaws' gap, the button up) and grip = <m>"},
      {"[probe]\nshape = \"grasper\"\nlength = 0.01\nopening = 0.02\ngrip = 0.03\nkeyframes = [[0.0, 0.0, 0.0, "
       "0.0]]",
       "grip: 0.03 is out of range: must lie in [0, opening)"},
      {"[probe]\nshape = \"grasper\"\nlength = 0.01\nopening = 0.02\ngrip = 0.01\nmode = \"grab\"\nkeyframes = "
       "[[0.0, 0.0, 0.0, 0.0]]",
       "a grasper has no mode"},
      {"[probe]\nradius = 0.005\ngrip = 0.01\nkeyframes = [[0.0, 0.0, 0.0, 0.0]]", "grip: only a grasper has it"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    const std::string message = error_of(sample("kind = \"implicit\"", c.text));
    EXPECT_NE(message.find(c.message), std::string::npos) << message;
    EXPECT_NE(message.find("scene.toml:"), std::string::npos) << message;
  }
}

TEST(Tools, AGrasperLiftsCarriesAndLetsGo) {
  // the jaws close 1.5 mm on each side of the sample (their gap 2.1 cm -> 1.8 cm), lift it 1 cm, carry it 2 cm
  // sideways, open, and it falls back onto the table
  const std::string table =
      "[[obstacle]]\nname = \"table\"\nplane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }\nfriction = "
      "0.5\n";
  SceneSession s = open_scene(
      parse_scene(sample("kind = \"implicit\"\ndt = 0.002",
                         table + grasper("[[0.0, 0.01, 0.0125, 0.01, 0.021], [0.1, 0.01, 0.0125, 0.01, 0.018], "
                                         "[0.3, 0.01, 0.0225, 0.01, 0.018], [0.5, 0.03, 0.0225, 0.01, 0.018], "
                                         "[0.55, 0.03, 0.0225, 0.01, 0.026]]"))),
      two_threads());
  Simulation& sim = *s.simulation;
  sim.run(0.5);
  const RunSummary carried = sim.summary();
  ASSERT_TRUE(carried.converged) << carried.failure;
  const Points u = sim.state().u;
  EXPECT_NEAR(u.row(0).mean(), 0.02, 0.002) << "carried 2 cm sideways";
  EXPECT_NEAR(u.row(1).mean(), 0.01, 0.0015) << "and 1 cm up";
  EXPECT_EQ(carried.obstacles.at(0).second.contacts, 0) << "off the table";
  const ToolSummary& held = tool(carried, "grasper");
  EXPECT_EQ(held.kind, "grasper");
  EXPECT_NEAR(held.force.y(), -weight, 0.05 * weight) << "the grasper carries its weight";
  EXPECT_NEAR(held.position.x(), 0.03, 1e-9) << "reported at the jaws' midpoint";
  ASSERT_EQ(carried.tools.size(), 1u) << "one tool, its two jaws summed";
  sim.run(0.3);  // opened at 0.55 s: let go
  const RunSummary dropped = sim.summary();
  ASSERT_TRUE(dropped.converged) << dropped.failure;
  EXPECT_LT(sim.state().u.row(1).mean(), 0.002) << "back on the table";
  EXPECT_NEAR(sim.state().u.row(0).mean(), 0.02, 0.003) << "where it was let go";
  EXPECT_EQ(tool(dropped, "grasper").contacts, 0) << "the jaws hold nothing";
  EXPECT_GT(dropped.obstacles.at(0).second.contacts, 0);
}

// a device's grasper (a virtual hand's script: [t, x, y, z, button], device frame, from the origin between the jaws
// at the sample's mid-height): its button closes the jaws from 2.1 to 1.8 cm over 0.1 s, the hand lifts 1 cm and
// carries 2 cm sideways, and lets the button go; the hand feels the sample's weight while it carries it
std::string device_grasper() {
  return R"(
[[obstacle]]
name = "table"
plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }
friction = 0.5
[[device]]
name = "hand"
[[tool]]
name = "grasper"
device = "hand"
shape = "grasper"
radius = 0.005
length = 0.016
orientation = [0.7071067811865476, -0.7071067811865476, 0.0, 0.0]
friction = 0.5
opening = 0.021
grip = 0.018
grip_time = 0.1
origin = [0.01, 0.0125, 0.01]
keyframes = [[0.0, 0.0, 0.0, 0.0, 1], [0.1, 0.0, 0.0, 0.0, 1], [0.3, 0.0, 0.01, 0.0, 1], [0.5, 0.02, 0.01, 0.0, 1], [0.55, 0.02, 0.01, 0.0, 0]]
)";
}

TEST(Tools, ADevicesGrasperClosesByItsButtonLiftsCarriesAndLetsGo) {
  const auto run = [](double duration) {
    SceneSession s = open_scene(
        parse_scene(sample(fmt::format("kind = \"implicit\"\ndt = 0.002\nduration = {}", duration), device_grasper()),
                    "scene.toml"),
        two_threads());
    InteractiveOptions o = s.interactive;
    o.real_time = false;
    o.log = false;
    EXPECT_EQ(o.probe.mode, ProbeMode::GRASP);
    const InteractiveResult r = run_interactive(*s.simulation, *s.device, o);
    RunSummary summary = s.simulation->summary();
    add_interactive_summary(summary, r);
    EXPECT_TRUE(s.simulation->posed_tool_loads().empty()) << "its jaws are reported as the hand, not besides it";
    return std::tuple(summary, Points(s.simulation->state().u), summary.tool);
  };
  const auto [carried, u, held] = run(0.5);
  ASSERT_TRUE(carried.converged) << carried.failure;
  // the hand follows its script with a lag (a mass on a spring); the sample goes with the grasper
  EXPECT_GT(u.row(0).mean(), 0.016) << "carried sideways";
  EXPECT_NEAR(u.row(0).mean(), held.position.x() - 0.01, 0.0015) << "with the grasper";
  EXPECT_NEAR(u.row(1).mean(), held.position.y() - 0.0125, 0.0015) << "and up with it";
  EXPECT_GT(u.row(1).mean(), 0.008);
  EXPECT_EQ(carried.obstacles.at(0).second.contacts, 0) << "off the table";
  EXPECT_EQ(held.kind, "grasper");
  EXPECT_NEAR(held.force.y(), -weight, 0.1 * weight) << "the hand feels the sample's weight";
  EXPECT_GT(held.contacts, 0);
  const auto [dropped, v, open] = run(0.85);
  ASSERT_TRUE(dropped.converged) << dropped.failure;
  EXPECT_LT(v.row(1).mean(), 0.002) << "let go: back on the table";
  EXPECT_GT(v.row(0).mean(), 0.016) << "where it was let go";
  EXPECT_EQ(open.contacts, 0) << "the jaws hold nothing";
  EXPECT_GT(dropped.obstacles.at(0).second.contacts, 0);
}

}  // namespace
