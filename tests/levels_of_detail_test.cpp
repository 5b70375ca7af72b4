// Tests for levels_of_detail (the layer between Simulation and the pipeline) and interactive runs with it: the
// active set replaces what is simulated, re-selection carries the state over without a jump in the force
// felt or added energy, re-selection on a worker thread, and runs report it.
#include <pointhaptics/haptics/contact.hpp>
#include <pointhaptics/haptics/devices/virtual_device.hpp>
#include <pointhaptics/lod/active_surface.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

// a block held at its bottom, 13 x 5 x 7 points
const char* block = R"(
[object]
shape = "box"
size = [0.12, 0.04, 0.06]
spacing = 0.01
[material]
young = 1e4
poisson = 0.4
density = 1000.0
damping = 30.0
[[fixed]]
box = { min = [-1.0, -1.0, -1.0], max = [1.0, 0.0, 1.0] }
[[load]]
kind = "point"
point = 0
force = [0.0, 0.0, 0.0]
[solver]
kind = "static"
)";

Scene block_scene(const Vec3& force, index_t point) {
  Scene s = parse_scene(block);
  s.loads[0].point = point;
  s.loads[0].force = force;
  return s;
}

index_t point_at(const Model& m, const Vec3& x) {
  index_t best = 0;
  for (index_t i = 0; i < m.n_points; ++i)
    if ((m.X.col(i) - x).norm() < (m.X.col(best) - x).norm()) best = i;
  return best;
}

TEST(LevelsOfDetail, SelectingEverythingSolvesLikeTheFullModel) {
  Model probe_model = build_scene_model(block_scene(Vec3::Zero(), 0));
  const index_t top = point_at(probe_model, Vec3(0.06, 0.04, 0.03));
  const Scene scene = block_scene(Vec3(0, -0.01, 0), top);
  Simulation full(build_scene_model(scene), scene.solver, 1), lod(build_scene_model(scene), scene.solver, 1);
  LodParams p;
  p.k1 = p.k2 = 50.0;
  lod.enable_lod(p, scene_lod_contact(scene, lod.model()));
  EXPECT_EQ(lod.simulated_model().n_points, full.model().n_points);
  full.step();
  lod.step();
  const RunSummary s = lod.summary();
  ASSERT_TRUE(s.converged);
  EXPECT_TRUE(s.lod.enabled);
  EXPECT_EQ(s.lod.selected, full.model().n_points);
  EXPECT_EQ(s.lod.selections, 1);
  const Points& a = full.state().u;
  const Points& b = lod.state().u;
  EXPECT_LE((a - b).norm(), 1e-6 * a.norm());
}

TEST(LevelsOfDetail, RunsOnTheActiveSetAndReportsIt) {
  Model m0 = build_scene_model(block_scene(Vec3::Zero(), 0));
  const index_t top = point_at(m0, Vec3(0.06, 0.04, 0.03));
  Scene scene = block_scene(Vec3(0, -0.01, 0), top);
  Simulation sim(build_scene_model(scene), scene.solver, 1);
  LodParams p;
  p.levels = {{3.0, 6}};
  sim.enable_lod(p, sim.model().X.col(top));
  EXPECT_LT(sim.simulated_model().n_points, sim.model().n_points);
  sim.step();
  const RunSummary s = sim.summary();
  ASSERT_TRUE(s.converged) << s.failure;
  EXPECT_EQ(s.lod.band_count.size(), 3u);
  EXPECT_EQ(s.lod.band_selected[0], s.lod.band_count[0]);  // everything within T_r1
  EXPECT_GT(s.lod.selected, 0);
  EXPECT_EQ(static_cast<index_t>(s.lod.active.size()), sim.model().n_points);
  EXPECT_TRUE(s.lod.active[top]);
  // the loaded point moved down; points far from the contact did not move at all
  const State& st = sim.state();
  EXPECT_LT(st.u(1, top), 0.0);
  const index_t far = point_at(sim.model(), Vec3(0.0, 0.04, 0.0));
  EXPECT_FALSE(s.lod.active[far]);
  EXPECT_EQ(st.u.col(far).norm(), 0.0);
  // the JSON marks active points
  const std::string json = result_json(sim.model(), st, s);
  EXPECT_NE(json.find("\"selections\": 1"), std::string::npos);
}

TEST(LevelsOfDetail, ReselectionCarriesTheStateWithoutAJumpInTheContactForce) {
  Scene scene = block_scene(Vec3::Zero(), 0);
  scene.loads.clear();
  scene.solver.kind = SolverKind::EXPLICIT;
  scene.solver.dt = 1e-3;
  Simulation sim(build_scene_model(scene), scene.solver, 1);
  LodParams p;
  p.k1 = 1.5;
  p.k2 = 2.0;
  p.levels = {{3.5, 5}};
  p.reselect = 0.5;
  const Vec3 c(0.05, 0.04, 0.03);
  sim.enable_lod(p, c);
  ProbeParams probe;
  probe.radius = 0.008;
  Vec3 probe_at = c + Vec3(0, probe.radius - 0.003, 0);  // pressed 3 mm into the top face
  // a coupling this stiff holds the probe where the device point is (within the contact force / 1e9 N/m);
  // re-selections in place, as in a deterministic run
  sim.attach_probe(probe, 1e9, 1e9, false);
  sim.inputs().device = probe_at;
  for (int k = 0; k < 150; ++k) ASSERT_NE(sim.step().status, StepStatus::FAILED);
  // the force a push probe at probe_at feels now (pushing has no memory: a fresh contact each time)
  auto felt = [&] {
    Points scratch = Points::Zero(3, sim.simulated_model().n_points);
    return ProbeContact(sim.simulated_model(), probe)
        .apply(sim.simulated_model(), sim.simulated_state().u, probe_at, false, sim.time(), scratch)
        .f0;
  };
  const Vec3 before = felt();
  ASSERT_GT(before.norm(), 1e-3);
  EXPECT_LE((sim.probe()->probe() - probe_at).norm(), 1e-6);
  // the probe slides by 0.8 h: beyond the re-selection distance
  const long long selections = sim.summary().lod.selections;
  probe_at.x() += 0.8 * sim.model().h;
  const Vec3 slid = felt();
  const Points u_before = sim.state().u;
  const std::vector<index_t> new_index = sim.update_lod(sim.lod_contact_of_probe(probe_at));
  ASSERT_FALSE(new_index.empty()) << "no re-selection";
  const Vec3 after = felt();
  EXPECT_LE((after - slid).norm(), 1e-9 * slid.norm())
      << "force before " << slid.transpose() << ", after " << after.transpose();
  // every point simulated before and after kept its displacement
  const Points u_after = sim.state().u;
  for (index_t k = 0; k < static_cast<index_t>(new_index.size()); ++k)
    if (new_index[k] >= 0) {
      const index_t i = sim.active_set()->full_of[new_index[k]];
      ASSERT_LE((u_after.col(i) - u_before.col(i)).norm(), 1e-15) << "point " << i;
    }
  EXPECT_EQ(sim.summary().lod.selections, selections + 1);
  // a small move does not re-select
  probe_at.x() += 0.1 * sim.model().h;
  EXPECT_TRUE(sim.update_lod(sim.lod_contact_of_probe(probe_at)).empty());
  // stepping on goes on smoothly, the probe's own contact renumbered with the points
  sim.inputs().device = probe_at;
  int touching = 0;  // the undamped block bounces against the probe: in contact at some steps
  for (int k = 0; k < 20; ++k) {
    ASSERT_NE(sim.step().status, StepStatus::FAILED);
    touching += sim.probe()->contact_model().contacts > 0;
  }
  EXPECT_TRUE(sim.state().u.allFinite());
  EXPECT_GT(touching, 5);
}

// a pressed, moving block with levels of detail: KE + strain energy of the simulated set
struct PressedBlock {
  Simulation sim;
  explicit PressedBlock(double reselect_interval) : sim(make()) {
    LodParams p;
    p.levels = {{3.0, 6}};
    p.reselect_interval = reselect_interval;
    sim.enable_lod(p, Vec3(0.03, 0.04, 0.03));
    // a bulge under the contact, released: the active set moves and deforms
    State st = sim.state();
    for (index_t i = 0; i < sim.model().n_points; ++i) {
      if (sim.model().fixed[i]) continue;
      const double r = (sim.model().X.col(i) - Vec3(0.03, 0.04, 0.03)).norm();
      st.u(1, i) = -0.004 * std::exp(-r * r / (0.015 * 0.015));
      st.velocity(1, i) = 0.05 * std::exp(-r * r / (0.02 * 0.02));
    }
    sim.set_state(st);
    for (int k = 0; k < 20; ++k) sim.step();
  }
  // of what is simulated
  double energy() {
    return strain_energy(sim.simulated_model(), sim.simulated_state().u).total() +
           kinetic_energy(sim.simulated_model(), sim.simulated_state().velocity);
  }
  static Simulation make() {
    Scene scene = block_scene(Vec3::Zero(), 0);
    scene.loads.clear();
    scene.solver.kind = SolverKind::EXPLICIT;
    return Simulation(build_scene_model(scene), scene.solver, 1);
  }
};

TEST(LevelsOfDetail, ATakeOverAddsNoEnergy) {
  // issue 21: seen through the new active set the same field held 30-100% more strain energy, and a slow
  // real-time session that re-selected often was pumped up until it diverged; the excess now comes out of
  // the kinetic energy
  PressedBlock b(0.0);
  int reselected = 0;
  for (const double x : {0.045, 0.06, 0.075, 0.09}) {
    const double before = b.energy();
    ASSERT_GT(before, 0);
    if (b.sim.update_lod(Vec3(x, 0.04, 0.03)).empty()) continue;
    ++reselected;
    EXPECT_LE(b.energy(), before * (1 + 1e-12)) << "re-selection at x = " << x;
    for (int k = 0; k < 5; ++k) b.sim.step();
  }
  EXPECT_EQ(reselected, 4);
}

TEST(LevelsOfDetail, ATakenOverStateIsSteppedWithTheSubStepsItsStretchNeeds) {
  // a new active set takes the deformed state over (set_state); its first explicit step planned its sub-steps
  // for the stiffening its fresh workspace had seen, none, so it took the rest state's sub-step where the probe
  // had stretched the object (a uniform stretch by half: 2.875 times stiffer, sqrt(1.25 / 2.875) of the step)
  Scene scene = parse_scene(block);
  scene.solver.kind = SolverKind::EXPLICIT;
  scene.fixed.clear();
  const double stable = Simulation(build_scene_model(scene), scene.solver, 1).stable_dt();
  scene.solver.dt = 0.99 * stable;
  Simulation sim(build_scene_model(scene), scene.solver, 1);
  EXPECT_EQ(sim.step().substeps, 1);
  State stretched = sim.state();
  stretched.u.row(0) = 0.5 * sim.model().X.row(0);
  stretched.velocity.setZero();
  sim.set_state(stretched);
  EXPECT_EQ(sim.step().substeps, 2);
}

TEST(LevelsOfDetail, NoReselectionSoonerThanTheIntervalAfterTheLast) {
  PressedBlock b(0.05);
  const double h = b.sim.model().h;
  ASSERT_FALSE(b.sim.update_lod(Vec3(0.03 + h, 0.04, 0.03)).empty());
  // 2 h further, 1 ms later: too soon
  b.sim.step();
  EXPECT_TRUE(b.sim.update_lod(Vec3(0.03 + 3 * h, 0.04, 0.03)).empty());
  // ... until the interval has passed
  while (b.sim.time() < 0.020 + 0.05 - 1e-9) b.sim.step();
  b.sim.step();
  EXPECT_FALSE(b.sim.update_lod(Vec3(0.03 + 3 * h, 0.04, 0.03)).empty());
  EXPECT_EQ(b.sim.lod_selections(), 3);
}

TEST(LevelsOfDetail, AsynchronousReselectionKeepsSteppingUntilTheNewSetTakesOver) {
  Scene scene = block_scene(Vec3::Zero(), 0);
  scene.loads.clear();
  scene.solver.kind = SolverKind::EXPLICIT;
  Simulation sim(build_scene_model(scene), scene.solver, 2);
  LodParams p;
  p.levels = {{3.0, 6}};
  const Vec3 c(0.03, 0.04, 0.03);
  sim.enable_lod(p, c);
  for (int k = 0; k < 5; ++k) sim.step();
  const index_t before = sim.simulated_model().n_points;  // new_index has an entry per old active point
  // moved by 2 h: a re-selection starts on a worker thread; this thread keeps stepping the old set
  const Vec3 moved = c + Vec3(2 * sim.model().h, 0, 0);
  EXPECT_TRUE(sim.update_lod(moved, false, true).empty());
  std::vector<index_t> new_index;
  int steps = 0;
  for (; steps < 100000 && new_index.empty(); ++steps) {
    sim.step();
    new_index = sim.update_lod(moved, false, true);
  }
  ASSERT_FALSE(new_index.empty()) << "the new active set never took over";
  EXPECT_EQ(static_cast<index_t>(new_index.size()), before);
  const RunSummary s = sim.summary();
  EXPECT_EQ(s.lod.selections, 2);
  EXPECT_LT(s.lod.max_reselect_ms, 1e4);
  // the new selection is around the moved contact: the point nearest it is simulated
  index_t nearest = 0;
  for (index_t i = 0; i < sim.model().n_points; ++i)
    if ((sim.model().X.col(i) - moved).norm() < (sim.model().X.col(nearest) - moved).norm()) nearest = i;
  EXPECT_TRUE(s.lod.active[nearest]);
  for (int k = 0; k < 10; ++k) sim.step();
  EXPECT_TRUE(sim.state().u.allFinite());
  // a re-selection still in flight when the simulation ends is waited for, not leaked
  sim.update_lod(c, false, true);
}

TEST(LevelsOfDetail, AWorkersReselectionGivesTheProbeThePartOfTheSurfaceItsActiveSetCarries) {
  // the part is made on the worker with the active set (it took 6 of the 9.7 ms a take-over held the shipped
  // half-sphere's simulation): the probe gets the same part as one made in place
  Scene scene = block_scene(Vec3::Zero(), 0);
  scene.loads.clear();
  scene.solver.kind = SolverKind::EXPLICIT;
  scene.probe.present = true;
  scene.probe.radius = 0.008;
  Simulation sim(build_scene_model(scene), scene.solver, 2);
  const auto surface = std::make_shared<const ObjectSurface>(build_object_surface(scene, sim.model()));
  LodParams p;
  p.levels = {{3.0, 6}};
  const Vec3 c(0.03, 0.04, 0.03);
  sim.enable_lod(p, c);
  sim.attach_probe(scene_interactive_options(scene, sim.model()).probe, 200.0, 3.3, true, surface);
  sim.inputs().device = c + Vec3(0, 0.02, 0);  // above the block
  for (int k = 0; k < 5; ++k) sim.step();
  const Vec3 moved = c + Vec3(2 * sim.model().h, 0, 0);
  EXPECT_TRUE(sim.update_lod(moved, false, true).empty());
  std::vector<index_t> new_index;
  for (int steps = 0; steps < 100000 && new_index.empty(); ++steps) {
    sim.step();
    new_index = sim.update_lod(moved, false, true);
  }
  ASSERT_FALSE(new_index.empty()) << "the new active set never took over";
  const SurfaceContact* contact = sim.probe()->surface_contact();
  ASSERT_NE(contact, nullptr);
  const ActiveSurface in_place = restrict_surface(surface->mesh, surface->map, *sim.active_set(), scene.probe.radius);
  ASSERT_GT(in_place.map.n_vertices(), 0);
  EXPECT_EQ(contact->map().n_vertices(), in_place.map.n_vertices());
  EXPECT_EQ(contact->map().points.index, in_place.map.points.index);
  EXPECT_EQ(contact->map().weight, in_place.map.weight);
  for (int k = 0; k < 10; ++k) sim.step();
  EXPECT_TRUE(sim.state().u.allFinite());
}

struct SlideResult {
  InteractiveResult run;
  RunSummary summary;
  index_t n_points = 0;
  Points last_frame;
};

// the probe presses 6 mm into the block's top, then slides 4 cm (2 h) along it
SlideResult slide(bool lod, LodScheme scheme = LodScheme::RANDOM) {
  Scene scene = block_scene(Vec3::Zero(), 0);
  scene.loads.clear();
  scene.solver.kind = SolverKind::EXPLICIT;
  scene.solver.duration = 1.0;
  scene.probe.present = true;
  scene.probe.radius = 0.008;
  scene.probe.keyframes = {{0.0, 0.0, 0.0, 0.0, 0}, {0.3, 0.0, -0.014, 0.0, 0}, {1.0, 0.04, -0.014, 0.0, 0}};
  Simulation sim(build_scene_model(scene), scene.solver, 1);
  LodParams p;
  p.levels = {{3.0, 6}};
  p.scheme = scheme;
  if (lod) sim.enable_lod(p, scene_lod_contact(scene, sim.model()));
  const auto device = make_scene_device(scene);
  InteractiveOptions o = scene_interactive_options(scene, sim.model());
  o.real_time = false;
  DisplayFrame blank;
  blank.u = Points::Zero(3, sim.model().n_points);
  TripleBuffer<DisplayFrame> display(blank);
  o.display = &display;
  SlideResult out;
  out.run = run_interactive(sim, *device, o);
  out.summary = sim.summary();
  out.n_points = sim.model().n_points;
  display.update();
  out.last_frame = display.front().u;
  return out;
}

double max_force_change(const std::vector<HapticLogRow>& log) {
  double m = 0;
  for (std::size_t k = 1; k < log.size(); ++k) m = std::max(m, (log[k].force - log[k - 1].force).norm());
  return m;
}

TEST(LevelsOfDetail, InteractiveRunsFollowTheProbe) {
  const SlideResult lod = slide(true, LodScheme::DITHER), full = slide(false), seed = slide(true, LodScheme::RANDOM);
  EXPECT_GT(lod.run.max_contacts, 0);
  EXPECT_GE(lod.summary.lod.selections, 3);  // 2 h of sliding, re-selecting every 0.5 h
  EXPECT_FALSE(full.summary.lod.enabled);
  // re-selection adds little of its own: with the dithered selection the force felt changes per tick about
  // as much as without levels of detail (sliding across this coarse lattice chatters by itself: 0.03-0.06 N
  // per tick); measured 0.073 N against 0.058 N. The seed's random selection re-draws a different far field
  // at every re-selection and the new active set starts out of balance: measured 0.151 N; a guard here
  double max_force = 0;
  for (const HapticLogRow& row : lod.run.log) max_force = std::max(max_force, row.force.norm());
  EXPECT_GT(max_force, 0.1);
  const double full_change = max_force_change(full.run.log);
  EXPECT_LT(max_force_change(lod.run.log), 1.4 * full_change + 0.005);
  EXPECT_LT(max_force_change(seed.run.log), 3.0 * full_change);
  RecordProperty("max_force_change_full", std::to_string(full_change));
  RecordProperty("max_force_change_dither", std::to_string(max_force_change(lod.run.log)));
  RecordProperty("max_force_change_random", std::to_string(max_force_change(seed.run.log)));
  // the display frames cover the whole object
  EXPECT_EQ(lod.last_frame.cols(), lod.n_points);
  EXPECT_TRUE(lod.last_frame.allFinite());
  EXPECT_GT(lod.last_frame.norm(), 0.0);
}

// The object's pairs across the plane x = 6.5 cm (between two planes of points) left unsevered
index_t unsevered_across(const Model& model) {
  index_t whole = 0;
  for (index_t i = 0; i < model.n_points; ++i)
    for (index_t e = model.neighbours.begin(i); e < model.neighbours.end(i); ++e) {
      const index_t j = model.neighbours.index[e];
      whole +=
          j > i && (model.X(0, i) < 0.065) != (model.X(0, j) < 0.065) && (model.severed.empty() || !model.severed[e]);
    }
  return whole;
}

TEST(LevelsOfDetail, ACutWhileAReselectionIsBuiltOnAWorkerReachesTheObjectAndTheNewSetOnceItIsBuilt) {
  Scene scene = block_scene(Vec3::Zero(), 0);
  scene.solver.kind = SolverKind::EXPLICIT;
  Simulation sim(build_scene_model(scene), scene.solver, 1);
  LodParams p;
  p.k1 = 2.5;  // x h = 5 cm
  p.k2 = 3.0;
  sim.enable_lod(p, Vec3(0.03, 0.04, 0.03));
  ASSERT_GT(unsevered_across(sim.model()), 0);
  // a re-selection around x = 9 cm built on a worker, and meanwhile a blade down through the plane x = 6.5 cm
  EXPECT_TRUE(sim.update_lod(Vec3(0.09, 0.04, 0.03), true, true).empty());
  const BladeSweep blade{Vec3(0.065, 0.05, -0.01), Vec3(0.065, 0.05, 0.07), Vec3(0.065, -0.01, -0.01),
                         Vec3(0.065, -0.01, 0.07)};
  const CutReport report = sim.cut(blade);
  EXPECT_GT(report.severed_pairs, 0);
  EXPECT_EQ(unsevered_across(sim.simulated_model()), 0);
  // the new set taken over (waiting for it): it and the object are cut all the way through
  EXPECT_FALSE(sim.update_lod(Vec3(0.09, 0.04, 0.03), true, false).empty());
  EXPECT_EQ(unsevered_across(sim.simulated_model()), 0);
  EXPECT_EQ(unsevered_across(sim.model()), 0);
  std::vector<index_t> piece_of;
  EXPECT_EQ(connected_pieces(sim.model(), piece_of), 2);
  EXPECT_EQ(sim.summary().cut.piece_points.size(), 2u);
  sim.step();
  EXPECT_TRUE(sim.state().u.allFinite());
}

}  // namespace
}  // namespace pointhaptics
