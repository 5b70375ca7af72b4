// Tests for the viewer's session: a scene prepared for viewing (the probe source, a static scene shown with
// dynamics), the deterministic frame of headless screenshots, the real-time run the mouse drives, and
// rebuilds from edited parameters (taken over while running; a bad one reported, the old run going on).
#include "viewer_session.hpp"

#include <pointhaptics/io/scene_toml.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <thread>

namespace pointhaptics::viewer {
namespace {

// the default scene: the seed's beam held at both ends, a scripted hand pressing its middle
Scene beam_scene() { return read_scene_file(PH_SCENES_DIR "/beam_probe.toml"); }

// wait (at most `seconds`) until `done` holds, polling the session as the viewer's frame loop does
template <class Done>
bool poll_until(ViewerSession& session, Done done, int seconds = 20) {
  for (int k = 0; k < 100 * seconds; ++k) {
    const bool took_over = session.poll();
    if (done(took_over)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

TEST(ViewerSession, ProbeSourcesAreNamedAndScriptsAreNeeded) {
  EXPECT_EQ(probe_source_of("mouse"), ProbeSource::MOUSE);
  EXPECT_THROW(probe_source_of("joystick"), Error);
  Scene scene = beam_scene();
  auto mouse = prepare(scene, ProbeSource::MOUSE, 1);
  ASSERT_NE(mouse->mouse, nullptr);
  EXPECT_EQ(mouse->device_name, "mouse");
  EXPECT_EQ(mouse->options.probe.mode, ProbeMode::PUSH_GRAB);  // push, and the button grabs
  EXPECT_EQ(mouse->reference.cols(), 90);
  EXPECT_NEAR(mouse->point_radius, 0.0075, 1e-12);
  // no device library here: auto falls back to the mouse
  scene.device.library = "libHD_missing.so";
  EXPECT_EQ(prepare(scene, ProbeSource::AUTO, 1)->device_name, "mouse");
  EXPECT_THROW(prepare(scene, ProbeSource::DEVICE, 1), Error);
  // a device that answers (a stand-in libHD built with the tests) drives the probe instead of the mouse
  scene.device.library = PH_FAKE_HD_PATH;
  auto device = prepare(scene, ProbeSource::AUTO, 1);
  EXPECT_EQ(device->device_name, "OpenHaptics device");
  EXPECT_EQ(device->mouse, nullptr);
  device.reset();  // releases the device
  scene.probe.keyframes.clear();
  EXPECT_THROW(prepare(scene, ProbeSource::SCRIPT, 1), Error);
  // a scene without a probe gets one, and levels of detail switched on in the panel start under it
  Scene bare = beam_scene();
  bare.probe = ProbeSpec{};
  bare.lod.present = true;
  auto lod = prepare(bare, ProbeSource::MOUSE, 1);
  ASSERT_TRUE(lod->simulation->lod_enabled());
  EXPECT_EQ(simulate_frame(*lod, 0.0).lod_band.size(), 0u);  // nothing published before a step
  const DisplayFrame stepped = simulate_frame(*lod, 0.05);
  ASSERT_EQ(stepped.lod_band.size(), 90u);
  EXPECT_LT(stepped.simulated, 90);
  EXPECT_EQ(static_cast<index_t>(
                std::count_if(stepped.lod_band.begin(), stepped.lod_band.end(), [](auto b) { return b >= 0; })),
            stepped.simulated);
  // a static scene is shown with implicit dynamics, and says so
  Scene still = beam_scene();
  still.solver.kind = SolverKind::STATIC;
  auto shown = prepare(still, ProbeSource::MOUSE, 1);
  EXPECT_EQ(shown->scene.solver.kind, SolverKind::IMPLICIT);
  EXPECT_FALSE(shown->note.empty());
}

TEST(ViewerSession, OnlyPointsNearTheSurfaceAreDrawnOfASolid) {
  Scene cube = beam_scene();
  cube.object.size = Vec3(0.2, 0.2, 0.2);
  cube.object.spacing = 0.01;
  cube.fixed.clear();
  const auto p = prepare(cube, ProbeSource::MOUSE, 1);
  const Eigen::Index n = p->reference.cols();
  ASSERT_EQ(n, 21 * 21 * 21);
  std::vector<char> drawn(static_cast<std::size_t>(n), 0);
  for (const index_t i : p->shell) drawn[static_cast<std::size_t>(i)] = 1;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Vec3 x = p->reference.col(i);
    const double depth = std::min(x.minCoeff(), (Vec3::Constant(0.2) - x).minCoeff());  // to the nearest face
    if (depth < 0.015) {
      EXPECT_TRUE(drawn[static_cast<std::size_t>(i)]) << "a point " << depth << " m under the surface";
    } else if (depth > 0.025) {
      EXPECT_FALSE(drawn[static_cast<std::size_t>(i)]) << "a hidden point " << depth << " m deep";
    }
  }
  EXPECT_EQ(p->shell.size(), static_cast<std::size_t>(n - 17 * 17 * 17));  // the two outer layers
}

TEST(ViewerSession, HeadlessFramesAreDeterministicAndFollowTheScript) {
  const Scene scene = beam_scene();
  auto a = prepare(scene, ProbeSource::SCRIPT, 1);
  auto b = prepare(scene, ProbeSource::SCRIPT, 1);
  const DisplayFrame start = simulate_frame(*a, 0.0);
  EXPECT_EQ(start.u.norm(), 0.0);
  EXPECT_TRUE(start.probe.isApprox(a->options.mapping.origin));
  const DisplayFrame fa = simulate_frame(*a, 0.8), fb = simulate_frame(*b, 0.8);
  EXPECT_NEAR(fa.time, 0.8, 1e-9);
  EXPECT_EQ(fa.u, fb.u);  // bit for bit
  EXPECT_GT(fa.contacts, 0);
  EXPECT_LT(fa.probe.y(), start.probe.y() - 0.01);  // the scripted hand brought it down
  EXPECT_LT(fa.u.row(1).minCoeff(), -1e-3);         // and pressed the beam
}

TEST(ViewerSession, AToolHeldAtAPositionBecomesTheMousesProbe) {
  Scene scene = beam_scene();
  scene.probe.keyframes.clear();
  scene.probe.position = Vec3(0.0675, 0.035, 0.015);
  scene.solver.kind = SolverKind::STATIC;
  auto p = prepare(scene, ProbeSource::MOUSE, 1);
  EXPECT_NE(p->note.find("the held tool is the mouse's probe"), std::string::npos) << p->note;
  EXPECT_EQ(p->simulation->held_tool(), nullptr);
  EXPECT_NEAR(simulate_frame(*p, 0.05).time, 0.05, 1e-9);
}

// two device-driven tools (scenes/two_hands_two_layers.toml, coarser): with the mouse each has a mouse device of
// its own, the cursor drives one at a time, and the one it left stays where it was; a script drives both instead
TEST(ViewerSession, TheMouseDrivesOneToolAtATimeAndTheOtherStaysWhereItLeftIt) {
  Scene scene = read_scene_file(PH_SCENES_DIR "/two_hands_two_layers.toml");
  for (BodySpec& b : scene.bodies) b.object.spacing = 0.005;
  auto p = prepare(scene, ProbeSource::MOUSE, 1);
  ASSERT_EQ(p->mice.size(), 2u);
  EXPECT_EQ(p->hand_names, (std::vector<std::string>{"finger", "probe"}));
  EXPECT_EQ(p->mouse, p->mice[0]);
  EXPECT_EQ(p->options.other_hands[0].device, p->mice[1]) << "not the scene's scripted device";
  drive_hand(*p, 1);
  EXPECT_EQ(p->driven, 1u);
  EXPECT_EQ(p->mouse, p->mice[1]);
  EXPECT_THROW(drive_hand(*p, 2), Error);
  // the cursor aims the second tool 6 mm to the side of its origin, in the air above the lower layer
  const Vec3 aim = hand_origin(*p, 1) + Vec3(0.006, 0.0, 0.0);
  p->mouse->set_target(device_of_scene(*p, aim, 1), 0u);
  const DisplayFrame f = simulate_frame(*p, 0.4);
  EXPECT_LT((f.probe - hand_origin(*p, 0)).norm(), 2e-4) << "the first tool stays at its origin";
  const auto second = std::find_if(f.rigid.begin(), f.rigid.end(), [](const auto& r) { return r.hand; });
  ASSERT_NE(second, f.rigid.end());
  EXPECT_LT((second->pose.position - aim).norm(), 1e-3) << second->pose.position.transpose();
  EXPECT_GT((second->pose.position - hand_origin(*p, 1)).norm(), 5e-3);

  auto scripted = prepare(scene, ProbeSource::SCRIPT, 1);
  EXPECT_TRUE(scripted->mice.empty());
  EXPECT_EQ(scripted->hand_names.size(), 2u);
  EXPECT_THROW(drive_hand(*scripted, 1), Error);
}

TEST(ViewerSession, TheMouseDrivesARealTimeRunAndEditsRebuildIt) {
  const Scene scene = beam_scene();
  ViewerSession session(prepare(scene, ProbeSource::MOUSE, 1), ProbeSource::MOUSE, 1);
  session.start();
  EXPECT_TRUE(session.running());
  // the probe is placed above the beam before the hand moves: a probe whose first placement is deep inside
  // the object pushes the surface out from within (under a sanitizer the first step came after the hand
  // had arrived)
  EXPECT_TRUE(poll_until(session, [&](bool) { return session.frame().time > 0.01; }));
  // the hand aims 2.5 cm below the probe's origin: into the beam's top face
  const Vec3 target = session.current().options.mapping.origin + Vec3(0, -0.025, 0);
  session.current().mouse->set_target(session.device_of_scene(target), 0u);
  // pressed in: under a sanitizer the simulation runs far behind the wall clock, so the hand is at its target
  // long before the beam gives; wait for the press itself, not for a simulated time
  EXPECT_TRUE(poll_until(session, [&](bool) {
    return session.frame().contacts > 0 && session.frame().time > 0.3 && session.frame().u.row(1).minCoeff() < -1e-3;
  }));
  EXPECT_GT(session.frame().haptic_ticks, 0);

  // an edit: stiffer, and the explicit solver swapped for the implicit one; the run goes on meanwhile
  Scene stiffer = session.current().scene;
  stiffer.material.young = 1e5;
  stiffer.solver.kind = SolverKind::IMPLICIT;
  session.rebuild(stiffer);
  EXPECT_TRUE(poll_until(session, [](bool took_over) { return took_over; }));
  EXPECT_DOUBLE_EQ(session.current().scene.material.young, 1e5);
  EXPECT_EQ(session.current().simulation->solver().kind, SolverKind::IMPLICIT);
  EXPECT_TRUE(session.running());
  EXPECT_TRUE(session.error().empty());
  session.current().mouse->set_target(Vec3::Zero(), 0u);
  EXPECT_TRUE(poll_until(session, [&](bool) { return session.frame().time > 0.2; }));

  // a bad edit is reported and the current run goes on
  Scene bad = session.current().scene;
  bad.object.spacing = -1;
  session.rebuild(bad);
  EXPECT_TRUE(poll_until(session, [&](bool) { return !session.error().empty(); }));
  EXPECT_FALSE(session.rebuilding());
  EXPECT_TRUE(session.running());
  EXPECT_DOUBLE_EQ(session.current().scene.material.young, 1e5);
  session.stop();
  EXPECT_FALSE(session.running());
}

TEST(ViewerSession, AScriptedCutSplitsTheDrawnSurfaceInAStillFrameAndInRealTime) {
  // scenes/cantilever_cut.toml: a blade through the beam's root from t = 0.2 s to 0.25 s
  const Scene scene = read_scene_file(PH_SCENES_DIR "/cantilever_cut.toml");
  auto still = prepare(scene, ProbeSource::MOUSE, 1);
  const index_t whole = static_cast<index_t>(still->drawn_surface()->mesh.F.size());
  EXPECT_EQ(still->drawn_surface()->cut_faces, 0);
  const DisplayFrame frame = simulate_frame(*still, 0.3);
  ASSERT_FALSE(frame.cut_sheets.empty());
  ASSERT_TRUE(still->cut_surface.has_value());
  EXPECT_EQ(still->cut_revision, frame.cut_revision);
  EXPECT_GT(still->drawn_surface()->cut_faces, 0);
  EXPECT_GT(static_cast<index_t>(still->drawn_surface()->mesh.F.size()), whole);
  EXPECT_EQ(still->drawn_surface_point().size(), static_cast<std::size_t>(still->drawn_surface()->mesh.V.cols()));

  // in real time the split is made on a worker and taken over by poll() (the blade reaches the beam at t = 0.2 s:
  // under a sanitizer the simulation runs far behind the wall clock)
  ViewerSession session(prepare(scene, ProbeSource::MOUSE, 1), ProbeSource::MOUSE, 1);
  session.start();
  // (the first strips are above the beam: a split of them has no faces inside it yet)
  EXPECT_TRUE(poll_until(
      session, [&](bool) { return session.current().cut_surface && session.current().cut_surface->cut_faces > 0; },
      300));
  EXPECT_GT(session.current().cut_revision, 0);
  session.stop();
}

}  // namespace
}  // namespace pointhaptics::viewer
