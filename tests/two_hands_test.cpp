// Two hands (issue 47): two [[tool]]s driven by two [[device]]s, each with its own haptic loop and local contact
// model, both touching every body. Read from a scene with named errors; no cross-talk (one hand's force moves by
// under 5% when the other presses elsewhere, and a hand that touches nothing renders nothing while the other
// presses); each hand's block in the result; and both loops ticking at the rate in real time.
#include <pointhaptics/session/interactive.hpp>
#include <pointhaptics/io/result_json.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/session/scene_session.hpp>

#include "support/scene_sessions.hpp"

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <string>

using namespace pointhaptics;

namespace {

using test::error_of;
using test::two_threads;

// a virtual device's keyframes: down by `depth` over 0.3 s, held to 0.6 s
std::string press(double depth) {
  return fmt::format("keyframes = [[0.0, 0.0, 0.0, 0.0], [0.3, 0.0, {:.4f}, 0.0], [0.6, 0.0, {:.4f}, 0.0]]", -depth,
                     -depth);
}

// two 4 x 2 x 4 cm blocks held at their bases, "left" from the origin and "right" 2 cm beside it, and two hands
// (spheres of 5 mm) whose devices start 1 cm above the middle of each block's top: "a" presses into the left block
// by `a_depth` of device travel over 0.3 s and holds, "b" into the right block by `b_depth`
std::string two_blocks_two_hands(double a_depth, double b_depth, const std::string& solver = "explicit",
                                 const std::string& more = "") {
  return fmt::format(R"(
[material]
young = 1e5
poisson = 0.3
density = 1000.0
damping = 20.0
[[object]]
name = "left"
shape = "box"
size = [0.04, 0.02, 0.04]
spacing = 0.005
[[object]]
name = "right"
shape = "box"
origin = [0.06, 0.0, 0.0]
size = [0.04, 0.02, 0.04]
spacing = 0.005
[[fixed]]
object = "left"
box = {{ min = [-1.0, -1.0, -1.0], max = [1.0, 0.001, 1.0] }}
[[fixed]]
object = "right"
box = {{ min = [-1.0, -1.0, -1.0], max = [1.0, 0.001, 1.0] }}
[solver]
kind = "{}"
dt = 1e-3
duration = 0.6
[[device]]
name = "left_hand"
[[device]]
name = "right_hand"
[[tool]]
name = "a"
radius = 0.005
device = "left_hand"
origin = [0.02, 0.03, 0.02]
{}
[[tool]]
name = "b"
radius = 0.005
device = "right_hand"
origin = [0.08, 0.03, 0.02]
{}
{}
)",
                     solver, press(a_depth), press(b_depth), more);
}

struct TwoHandRun {
  InteractiveResult result;
  RunSummary summary;
  nlohmann::json json;                  ///< the result document
  std::vector<HapticLogRow> first_log;  ///< each hand's force log, streamed
  std::vector<HapticLogRow> second_log;
};

TwoHandRun run(const std::string& text, bool real_time = false) {
  SceneSession s = open_scene(parse_scene(text, "scene.toml"), two_threads());
  InteractiveOptions options = s.interactive;
  options.real_time = real_time;
  options.log = false;
  TwoHandRun r;
  options.log_sink = [&r](const HapticLogRow& row) { r.first_log.push_back(row); };
  if (!options.other_hands.empty())
    options.other_hands[0].log_sink = [&r](const HapticLogRow& row) { r.second_log.push_back(row); };
  r.result = run_interactive(*s.simulation, *s.device, options);
  r.summary = s.simulation->summary();
  add_interactive_summary(r.summary, r.result);
  r.json = nlohmann::json::parse(result_json(s.simulation->model(), s.simulation->state(), r.summary));
  return r;
}

TEST(TwoHands, AreReadAsTheProbeAndOneMoreHand) {
  const Scene scene = parse_scene(two_blocks_two_hands(0.016, 0.016), "scene.toml");
  EXPECT_TRUE(scene.probe.present);
  EXPECT_EQ(scene.probe_name, "a");
  ASSERT_EQ(scene.other_hands.size(), 1u);
  EXPECT_EQ(scene.other_hands[0].name, "b");
  EXPECT_EQ(scene.other_hands[0].probe.origin, Vec3(0.08, 0.03, 0.02));
  EXPECT_TRUE(scene.tools.empty()) << "no posed tools";
  const SceneSession s = open_scene(scene, two_threads());
  ASSERT_EQ(s.other_devices.size(), 1u);
  ASSERT_EQ(s.interactive.other_hands.size(), 1u);
  EXPECT_EQ(s.interactive.other_hands[0].device, s.other_devices[0].get());
  EXPECT_EQ(s.interactive.other_hands[0].mapping.origin, Vec3(0.08, 0.03, 0.02));
  EXPECT_NE(s.interactive.other_hands[0].surface, nullptr) << "it pushes on the bodies' surface";
}

TEST(TwoHands, AViewerPutsTheToolItDrivesFirst) {
  Scene scene = parse_scene(two_blocks_two_hands(0.016, 0.008), "scene.toml");
  put_hand_first(scene, "b");
  EXPECT_EQ(scene.probe_name, "b");
  EXPECT_EQ(scene.probe.origin, Vec3(0.08, 0.03, 0.02));
  ASSERT_EQ(scene.other_hands.size(), 1u);
  EXPECT_EQ(scene.other_hands[0].name, "a");
  EXPECT_EQ(scene.other_hands[0].probe.origin, Vec3(0.02, 0.03, 0.02));
  put_hand_first(scene, "b");  // already first
  EXPECT_EQ(scene.probe_name, "b");
  try {
    put_hand_first(scene, "c");
    FAIL() << "no tool c";
  } catch (const Error& e) {
    EXPECT_NE(
        std::string(e.what()).find("no device-driven tool is named \"c\" (the device-driven tools: \"b\", \"a\")"),
        std::string::npos)
        << e.what();
  }
}

TEST(TwoHands, MistakesAreNamed) {
  // a second hand with levels of detail
  const std::string lod = error_of(two_blocks_two_hands(0.01, 0.01, "explicit", "[lod]\nk1 = 1.0"), false);
  EXPECT_NE(lod.find("tool \"b\""), std::string::npos) << lod;
  EXPECT_NE(lod.find("levels of detail"), std::string::npos) << lod;
  // a static solve
  const std::string statics = error_of(two_blocks_two_hands(0.01, 0.01, "static"), false);
  EXPECT_NE(statics.find("static solve"), std::string::npos) << statics;
  // a second hand's virtual device with nothing to follow
  std::string text = two_blocks_two_hands(0.01, 0.01);
  text.erase(text.rfind(press(0.01)), press(0.01).size());
  const std::string script = error_of(text, false);
  EXPECT_NE(script.find("tool \"b\": a virtual device needs"), std::string::npos) << script;
  // two tools on one device
  std::string shared = two_blocks_two_hands(0.01, 0.01);
  shared.replace(shared.find("device = \"right_hand\""), 21, "device = \"left_hand\"");
  const std::string one_device = error_of(shared, false);
  EXPECT_NE(one_device.find("one tool per device"), std::string::npos) << one_device;
}

TEST(TwoHands, OneHandsForceIsItsOwnWhateverTheOtherDoes) {
  // "a" presses the left block alone, then while "b" presses the right one, 10 mm of device travel each: deeper, the
  // 5 mm probe on the 5 mm lattice's surface leans to one side (at 12 mm a lateral force of 0.15 of the normal one),
  // which way depending on round-off (under the sanitizers it flipped between the two runs)
  const TwoHandRun alone = run(two_blocks_two_hands(0.010, 0.0));
  const TwoHandRun both = run(two_blocks_two_hands(0.010, 0.010));
  ASSERT_EQ(alone.result.other_hands.size(), 1u);
  ASSERT_EQ(both.result.other_hands.size(), 1u);
  for (const TwoHandRun* r : {&alone, &both}) {
    EXPECT_FALSE(r->result.haptic.device_failed);
    EXPECT_EQ(r->result.haptic.ticks, 600);
    EXPECT_EQ(r->result.other_hands[0].haptic.ticks, 600) << "each hand has its own loop, ticking at the rate";
  }
  const Vec3 a_alone = alone.result.tool.force, a_both = both.result.tool.force;
  const Vec3 b_both = both.result.other_hands[0].tool.force;
  // each presses its block: the blocks push up on the probes
  EXPECT_GT(a_alone.y(), 0.2) << a_alone.transpose();
  EXPECT_GT(b_both.y(), 0.2) << b_both.transpose();
  EXPECT_GT(both.result.other_hands[0].max_contacts, 0);
  // no cross-talk: "a" feels its own block whatever "b" does (SOFA users report two devices rendering the first
  // one's force)
  EXPECT_LT((a_both - a_alone).norm(), 0.05 * a_alone.norm())
      << "alone " << a_alone.transpose() << ", with b pressing " << a_both.transpose();
  EXPECT_LT(alone.result.other_hands[0].haptic.max_force_n, 1e-3 * alone.result.haptic.max_force_n)
      << "b touches nothing: its device is commanded nothing while a presses";
  EXPECT_GT(both.result.other_hands[0].haptic.max_force_n, 0.5 * both.result.haptic.max_force_n);
  // each hand's force log is its own: a row per tick of its loop, carrying the force its device was commanded
  const auto largest = [](const std::vector<HapticLogRow>& log) {
    double f = 0;
    for (const HapticLogRow& row : log) f = std::max(f, row.force.norm());
    return f;
  };
  for (const TwoHandRun* r : {&alone, &both}) {
    EXPECT_EQ(r->first_log.size(), 600u);
    EXPECT_EQ(r->second_log.size(), 600u);
    EXPECT_EQ(r->result.other_hands[0].log_dropped, 0);
    EXPECT_NEAR(largest(r->first_log), r->result.haptic.max_force_n, 1e-9);
    EXPECT_NEAR(largest(r->second_log), r->result.other_hands[0].haptic.max_force_n, 1e-9);
  }
  EXPECT_LT(largest(alone.second_log), 1e-3 * largest(alone.first_log)) << "b's log is b's, not a's";
  // the result: both hands in `tools`, each with its own haptic figures
  const nlohmann::json& doc = both.json;
  ASSERT_TRUE(doc.contains("tools")) << doc.dump();
  ASSERT_TRUE(doc["tools"].contains("a") && doc["tools"].contains("b")) << doc["tools"].dump();
  EXPECT_EQ(doc["tools"]["b"]["haptic"]["ticks"], 600);
  EXPECT_NEAR(doc["tools"]["b"]["force"][1].get<double>(), b_both.y(), 1e-12);
  EXPECT_NEAR(doc["tools"]["a"]["force"][1].get<double>(), a_both.y(), 1e-12);
}

TEST(TwoHands, BothTouchOneBody) {
  // "b" moved over the left block's far corner: both press the same body, each feels it
  std::string text = two_blocks_two_hands(0.016, 0.016);
  text.replace(text.find("origin = [0.08, 0.03, 0.02]"), 27, "origin = [0.032, 0.03, 0.032]");
  const TwoHandRun r = run(text);
  EXPECT_GT(r.result.tool.force.y(), 0.2);
  EXPECT_GT(r.result.other_hands[0].tool.force.y(), 0.2);
  EXPECT_GT(r.summary.bodies.at(0).max_displacement, 10 * r.summary.bodies.at(1).max_displacement)
      << "the left block is the one pressed";
}

TEST(TwoHands, InRealTimeNeitherLoopWaits) {
  const TwoHandRun r = run(two_blocks_two_hands(0.016, 0.016), true);
  ASSERT_EQ(r.result.other_hands.size(), 1u);
  EXPECT_FALSE(r.result.haptic.device_failed);
  for (const HapticStats& h : {r.result.haptic, r.result.other_hands[0].haptic}) {
    EXPECT_GT(h.ticks, 400) << "0.6 s at 1 kHz, each loop on its own thread";
    EXPECT_GT(h.max_force_n, 0.1);
  }
}

}  // namespace
