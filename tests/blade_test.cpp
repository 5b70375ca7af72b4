// Tests for the blade (ProbeMode::CUT, tools/probe_tool.cpp with mechanics/cut.cpp): a device's blade passed
// through the cantilever near its root with the button held cuts it in two, the hand feels the cutting
// resistance against the blade's move, the work it does is the resistance times the cut area, and the force
// felt is continuous, bounded and finite.
#include <pointhaptics/haptics/devices/virtual_device.hpp>
#include <pointhaptics/session/interactive.hpp>
#include <pointhaptics/lod/active_surface.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/surface/cut_surface.hpp>
#include <pointhaptics/surface/object_surface.hpp>
#include <pointhaptics/session/scene_builder.hpp>

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>

namespace pointhaptics {
namespace {

constexpr double resistance = 50.0;  // J/m^2

// scenes/cantilever_cut.toml's beam (0.15 x 0.03 x 0.03 m, E = 1e6 Pa, under its weight) without its script
Scene beam() {
  Scene scene = read_scene_file(PH_SCENES "/cantilever_cut.toml");
  scene.cuts.clear();
  return scene;
}

// a blade 5 cm long along z (identity orientation: the capsule's axis) with the device's origin at `origin`, in
// simulated time
InteractiveOptions blade(const Vec3& origin, double duration) {
  InteractiveOptions o;
  o.probe.radius = 0.001;
  o.probe.length = 0.05;
  o.probe.mode = ProbeMode::CUT;
  o.probe.cut_resistance = resistance;
  o.mapping.origin = origin;
  o.duration = duration;
  o.real_time = false;
  return o;
}

TEST(Blade, ADevicesBladeCutsTheCantileverThroughAndTheHandFeelsTheResistance) {
  const Scene scene = beam();
  Simulation sim(build_scene_model(scene), scene.solver, 2);
  const Model& model = sim.model();
  // the blade's centre in the plane x = 3.375 cm, moved from 2 cm above the beam to 2 cm below it between
  // t = 0.05 s and 0.25 s (0.35 m/s), button held
  const Vec3 above(0.03375, 0.05, 0.015), below(0.03375, -0.02, 0.015);
  VirtualDevice device(Trajectory({{0.0, Vec3::Zero(), true},
                                   {0.05, Vec3::Zero(), true},
                                   {0.25, below - above, true},
                                   {0.4, below - above, true}}),
                       known_device_specs("touch"));
  InteractiveOptions o = blade(above, 0.4);
  double work = 0, largest = 0, largest_step = 0;
  Vec3 last_probe = Vec3::Constant(NAN), last_force = Vec3::Zero();
  o.after_step = [&](long long) {
    const ProbeTool* tool = sim.probe();
    ASSERT_TRUE(tool->cutting());
    const Vec3 f = tool->contact_model().f0;
    ASSERT_TRUE(f.allFinite());
    if (last_probe.allFinite()) work -= f.dot(tool->probe() - last_probe);  // the hand's work against it
    largest = std::max(largest, f.norm());
    largest_step = std::max(largest_step, (f - last_force).norm());
    last_probe = tool->probe();
    last_force = f;
  };
  const InteractiveResult r = run_interactive(sim, device, o);
  ASSERT_FALSE(sim.diagnostics().failed) << sim.diagnostics().failure;
  const RunSummary s = sim.summary();
  ASSERT_TRUE(s.cut.present);
  ASSERT_EQ(s.cut.piece_points.size(), 2u);
  EXPECT_EQ(s.cut.piece_points[0], 125);
  EXPECT_EQ(s.cut.piece_points[1], 400);
  // the area the severed pairs stand for, against the section's 9 cm^2: the pairs near the faces are fewer
  // (a point on a face has no neighbours beyond it)
  const double area = cut_area(model, s.cut.cut_pairs);
  EXPECT_NEAR(area, 9e-4, 0.25 * 9e-4);
  // the hand's work against the resistance is G times that area (the low-pass delays the force, and the
  // blade still moves while it dies out)
  EXPECT_NEAR(work, resistance * area, 0.1 * resistance * area);
  // through the section's 3 cm the blade is held back by about G x 3 cm; the force rises and falls smoothly
  EXPECT_GT(largest, 0.6 * resistance * 0.03);
  EXPECT_LT(largest, 1.6 * resistance * 0.03);
  EXPECT_LT(largest_step, 0.25 * largest);
  // what the device was sent stays finite and within its limit
  double sent = 0;
  for (const auto& tick : r.log) {
    ASSERT_TRUE(tick.force.allFinite());
    sent = std::max(sent, tick.force.norm());
  }
  EXPECT_LE(sent, known_device_specs("touch").max_force + 1e-9);
  std::printf(
      "cut pairs %lld, area %.4g m^2, work %.4g J (G A = %.4g J), largest force %.3g N (G x 3 cm = %.3g N), "
      "largest step-to-step change %.3g N, longest sweep %.3g ms\n",
      s.cut.cut_pairs, area, work, resistance * area, largest, resistance * 0.03, largest_step, s.cut.max_update_ms);
}

// Levels of detail around the root (the points within 2.25 cm of the top of the cut plane, part of those to 2.85 cm;
// nothing beyond): the section's bottom lies outside, so the cut there is the object's only
LodParams root_lod() {
  LodParams p;
  p.k1 = 1.5;  // x h = 1.5 cm
  p.k2 = 1.9;
  return p;
}
const Vec3 cut_top(0.03375, 0.03, 0.015);

// the blade cuts through as above with the probe on the object's surface; the button let go below the beam,
// it goes round (beside the beam in z), waits in the gap the falling piece leaves, and is pushed 1.4 cm into
// the stump's cut face at x = 3.375 cm; with levels of detail or without.
// With levels of detail the piece lies outside the active set and does not fall (0.1 mm): there is no gap,
// and the hand's way in goes through the piece's side (z = 3 cm). The blade (radius 1 mm, 5 cm long along z)
// passed between that face's vertices and reached the cut face only by going through the piece; then its
// centre was held on the face (the god-object's test of its path), where no vertex reached it, and the hand
// felt nothing. The contact's samples on the triangles (edges of at most the blade's radius) now catch its
// end on the piece's side: it is held there, and the hand pulling it in feels the side push back.
void lifted_blade_stops_at_the_cut_face(bool levels_of_detail) {
  const Scene scene = beam();
  Simulation sim(build_scene_model(scene), scene.solver, 2);
  if (levels_of_detail) sim.enable_lod(root_lod(), cut_top);
  const auto whole = std::make_shared<const ObjectSurface>(build_object_surface(scene, sim.model()));
  const Vec3 above(0.03375, 0.05, 0.015);
  VirtualDevice device(Trajectory({{0.0, Vec3::Zero(), true},
                                   {0.05, Vec3::Zero(), true},
                                   {0.25, Vec3(0, -0.07, 0), true},
                                   {0.27, Vec3(0, -0.07, 0), false},
                                   {0.30, Vec3(0, -0.07, 0.045), false},
                                   {0.35, Vec3(0.0165, -0.07, 0.045), false},
                                   {0.40, Vec3(0.0165, -0.035, 0.045), false},
                                   {0.55, Vec3(0.0165, -0.035, 0), false},
                                   {0.75, Vec3(-0.0135, -0.035, 0), false},
                                   {0.85, Vec3(-0.0135, -0.035, 0), false}}),
                       known_device_specs("touch"));
  InteractiveOptions o = blade(above, 0.85);
  o.surface = whole;
  Vec3 probe = Vec3::Constant(NAN), force = Vec3::Constant(NAN);
  index_t vertices = 0;
  double reach = 0;
  o.after_step = [&](long long) {  // (the probe is detached when the run ends)
    const ProbeTool* tool = sim.probe();
    probe = tool->probe();
    force = tool->contact_model().f0;
    vertices = tool->on_surface() ? tool->surface_contact()->map().n_vertices() : 0;
    reach = tool->on_surface() ? tool_reach(tool->surface_contact()->shape()) : 0.0;
  };
  run_interactive(sim, device, o);
  ASSERT_FALSE(sim.diagnostics().failed) << sim.diagnostics().failure;
  const RunSummary s = sim.summary();
  ASSERT_EQ(s.cut.piece_points.size(), 2u);
  // once the button was let go the probe's surface was split along the stroke's sheets, once
  EXPECT_EQ(s.cut.surface_splits, 1);
  // (with levels of detail, than the part of the uncut surface the active set carries)
  const index_t uncut = levels_of_detail
                            ? restrict_surface(whole->mesh, whole->map, *sim.active_set(), reach).map.n_vertices()
                            : whole->map.n_vertices();
  EXPECT_GT(vertices, uncut);
  const double face = 0.03375 + 0.001;
  if (levels_of_detail) {
    // held on the piece's side, not through it: its end (2.6 cm from its centre) on the face z = 3 cm, pushed
    // back out along z (1.34 N; nothing before the samples)
    EXPECT_GE(probe.z(), 0.03 + 0.025) << probe.transpose();
    EXPECT_GT(probe.x(), 0.045) << probe.transpose();
    EXPECT_GT(force.z(), 0.5) << force.transpose();
  } else {
    // the blade (radius 1 mm) stands on the stump's cut face, pushed back along +x; the hand is 1.4 cm beyond
    EXPECT_NEAR(probe.x(), face, 0.0015) << probe.transpose();
    EXPECT_GT(force.x(), 0.5);
    // within 14 degrees of the face's normal: the blade dents the face it is pushed into (-0.17 N along y for
    // 0.84 N along x with the contact's samples on the face's triangles, 0.05 for 0.92 on its vertices alone)
    EXPECT_LT(std::abs(force.y()), 0.25 * force.x());
  }
  std::printf(
      "lifted blade%s: at (%.5f, %.5f, %.5f) m against the face at x = %.5f m, force (%.3g, %.3g, %.3g) N, split in %.2f ms\n",
      levels_of_detail ? " (levels of detail)" : "", probe.x(), probe.y(), probe.z(), face, force.x(), force.y(),
      force.z(), s.cut.max_split_ms);
}

TEST(Blade, LiftedAfterAStrokeTheBladePushesOnTheSplitSurfaceAndStopsAtTheCutFace) {
  lifted_blade_stops_at_the_cut_face(false);
}

TEST(Blade, WithLevelsOfDetailTheLiftedBladeTouchesTheActiveSetsPartOfTheSplitSurfaceAndIsHeldOnThePiece) {
  lifted_blade_stops_at_the_cut_face(true);
}

TEST(Blade, SawingForASecondStaysFiniteBoundedAndWithinTheDevice) {
  // the blade sawed back and forth along the beam's root region while it sinks, a thousand steps: every step
  // cuts; nothing non-finite, the simulation never fails, the device's force stays within its limit
  const Scene scene = beam();
  Simulation sim(build_scene_model(scene), scene.solver, 2);
  const Vec3 origin(0.03375, 0.04, 0.015);
  std::vector<Keyframe> saw;
  for (int k = 0; k <= 20; ++k)  // 20 strokes of 5 cm in x, 3 mm deeper each
    saw.push_back({0.05 * k, Vec3((k % 2 ? 0.05 : 0.0), -0.003 * k, 0.0), true});
  VirtualDevice device{Trajectory(std::move(saw)), known_device_specs("touch")};
  InteractiveOptions o = blade(origin, 1.0);
  long long steps = 0;
  o.after_step = [&](long long) {
    ++steps;
    ASSERT_TRUE(sim.probe()->contact_model().f0.allFinite());
    ASSERT_TRUE(sim.probe()->blade_trail().size() <= ProbeTool::blade_trail_steps);
    ASSERT_TRUE(sim.probe()->cut_history_size() <= ProbeTool::cut_history_steps);
  };
  const InteractiveResult r = run_interactive(sim, device, o);
  ASSERT_FALSE(sim.diagnostics().failed) << sim.diagnostics().failure;
  EXPECT_EQ(steps, 1000);
  EXPECT_TRUE(sim.state().u.allFinite());
  const RunSummary s = sim.summary();
  EXPECT_GT(s.cut.cut_pairs, 100);
  EXPECT_EQ(static_cast<index_t>(sim.model().severed.size()), sim.model().n_pairs());
  // the cut's sheets: at most a strip (two triangles) per step, fewer where strips run on straight
  const std::size_t sheets = sim.cut_sheets().triangles.size();
  EXPECT_GT(sheets, 0u);
  EXPECT_LE(sheets, 2u * 1000u);
  // and the surface split along them all (sheets sawn back and forth over one another): finite, and carried
  const auto start = std::chrono::steady_clock::now();
  const ObjectSurface split =
      split_surface(build_object_surface(scene, sim.model()), sim.model(), sim.cut_sheets().triangles);
  const double split_ms = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GT(split.cut_faces, 0);
  EXPECT_TRUE(split.mesh.V.allFinite());
  EXPECT_TRUE(deformed_surface(split, sim.state().u).allFinite());
  std::printf("sawn surface: %zu triangles, %lld faces of cuts, split in %.0f ms (%s)\n", split.mesh.F.size(),
              static_cast<long long>(split.cut_faces), split_ms, split.source.c_str());
  for (const auto& tick : r.log) {
    ASSERT_TRUE(tick.force.allFinite());
    ASSERT_LE(tick.force.norm(), known_device_specs("touch").max_force + 1e-9);
  }
  std::printf("sawing: %lld pairs cut, %zu pieces, a sweep %.3f ms on average, %.3f ms at most, %zu sheet triangles\n",
              s.cut.cut_pairs, s.cut.piece_points.size(), s.cut.mean_update_ms, s.cut.max_update_ms, sheets);
}

// No unsevered pair of `model` crosses the plane x = 3.375 cm (reference configuration); the pairs that do, counted
index_t pairs_across_the_cut(const Model& model, index_t& severed) {
  index_t whole = 0;
  severed = 0;
  for (index_t i = 0; i < model.n_points; ++i)
    for (index_t e = model.neighbours.begin(i); e < model.neighbours.end(i); ++e) {
      const index_t j = model.neighbours.index[e];
      if (j < i || (model.X(0, i) < 0.03375) == (model.X(0, j) < 0.03375)) continue;
      if (!model.severed.empty() && model.severed[e]) ++severed;
      else ++whole;
    }
  return whole;
}

TEST(Blade, WithLevelsOfDetailAScriptedCutInTheActiveSetReachesTheObjectAndTheNextActiveSets) {
  const Scene scene = read_scene_file(PH_SCENES "/cantilever_cut.toml");
  // without levels of detail, for comparison
  Simulation plain(build_scene_model(scene), scene.solver, 2);
  for (const CutSpec& cut : scene.cuts) plain.add_scripted_cut(cut);
  plain.run(0.3);
  const RunSummary p = plain.summary();
  Simulation sim(build_scene_model(scene), scene.solver, 2);
  for (const CutSpec& cut : scene.cuts) sim.add_scripted_cut(cut);
  sim.enable_lod(root_lod(), cut_top);
  const index_t object_points = sim.model().n_points, simulated = sim.simulated_model().n_points;
  EXPECT_LT(sim.active_set()->n_selected, object_points / 2);
  // part of the section is not simulated: the points on its two sides at the bottom lie beyond the bands
  index_t bottom_simulated = 0;
  for (index_t k = 0; k < sim.active_set()->n_selected; ++k) {
    const Vec3 X = sim.model().X.col(sim.active_set()->full_of[k]);
    bottom_simulated += std::abs(X.x() - 0.03375) < 0.004 && X.y() < 1e-9;
  }
  EXPECT_EQ(bottom_simulated, 0);
  sim.run(0.3);
  ASSERT_FALSE(sim.diagnostics().failed) << sim.diagnostics().failure;
  const RunSummary s = sim.summary();
  ASSERT_TRUE(s.cut.present);
  // the object is in two pieces, as without levels of detail, and the same pairs (to the few at the section's
  // rim, where the sheets mapped back and the current positions may differ)
  ASSERT_EQ(s.cut.piece_points.size(), 2u);
  EXPECT_EQ(s.cut.piece_points, p.cut.piece_points);
  EXPECT_NEAR(static_cast<double>(s.cut.cut_pairs), static_cast<double>(p.cut.cut_pairs),
              0.05 * static_cast<double>(p.cut.cut_pairs));
  index_t severed = 0;
  EXPECT_EQ(pairs_across_the_cut(sim.model(), severed), 0);
  EXPECT_EQ(severed, s.cut.cut_pairs);
  // the active set too
  EXPECT_EQ(pairs_across_the_cut(sim.simulated_model(), severed), 0);
  EXPECT_GT(severed, 0);
  // a new active set elsewhere, then back at the cut: built from the cut object, both pieces in it
  EXPECT_FALSE(sim.update_lod(Vec3(0.12, 0.03, 0.015), true).empty());
  EXPECT_FALSE(sim.update_lod(cut_top + Vec3(0, 0, 0.005), true).empty());
  const Model& again = sim.simulated_model();
  EXPECT_EQ(pairs_across_the_cut(again, severed), 0);
  EXPECT_GT(severed, 0);
  std::vector<index_t> piece_of;
  EXPECT_EQ(connected_pieces(again, piece_of), 2);
  sim.run(0.35);
  ASSERT_FALSE(sim.diagnostics().failed) << sim.diagnostics().failure;
  EXPECT_TRUE(sim.state().u.allFinite());
  std::printf(
      "levels of detail: %lld of %lld points simulated; %lld pairs cut in the object (%lld without levels of detail), "
      "pieces %zu\n",
      static_cast<long long>(simulated), static_cast<long long>(object_points), s.cut.cut_pairs, p.cut.cut_pairs,
      s.cut.piece_points.size());
}

TEST(Blade, WithLevelsOfDetailADevicesBladeCutsTheObjectThrough) {
  // the stroke of the first test, with levels of detail following the blade (the points near it simulated)
  const Scene scene = beam();
  Simulation sim(build_scene_model(scene), scene.solver, 2);
  sim.enable_lod(root_lod(), cut_top);
  const Vec3 above(0.03375, 0.05, 0.015), below(0.03375, -0.02, 0.015);
  VirtualDevice device(Trajectory({{0.0, Vec3::Zero(), true},
                                   {0.05, Vec3::Zero(), true},
                                   {0.25, below - above, true},
                                   {0.4, below - above, true}}),
                       known_device_specs("touch"));
  InteractiveOptions o = blade(above, 0.4);
  double largest = 0;
  o.after_step = [&](long long) { largest = std::max(largest, sim.probe()->contact_model().f0.norm()); };
  const InteractiveResult r = run_interactive(sim, device, o);
  ASSERT_FALSE(sim.diagnostics().failed) << sim.diagnostics().failure;
  const RunSummary s = sim.summary();
  ASSERT_EQ(s.cut.piece_points.size(), 2u);
  EXPECT_EQ(s.cut.piece_points[0], 125);
  EXPECT_EQ(s.cut.piece_points[1], 400);
  index_t severed = 0;
  EXPECT_EQ(pairs_across_the_cut(sim.model(), severed), 0);
  EXPECT_GT(s.lod.selections, 1);  // the active set followed the blade
  // the hand felt the resistance, as without levels of detail
  EXPECT_GT(largest, 0.6 * resistance * 0.03);
  EXPECT_LT(largest, 1.6 * resistance * 0.03);
  for (const auto& tick : r.log) ASSERT_TRUE(tick.force.allFinite());
  std::printf(
      "a blade with levels of detail: %lld pairs cut, %lld selections, largest force %.3g N, longest update %.3g ms\n",
      s.cut.cut_pairs, s.lod.selections, largest, s.cut.max_update_ms);
}

}  // namespace
}  // namespace pointhaptics
