// Tests for the probe on the object's surface (issue 16): pressed slowly into a block, explicit and implicit
// dynamics render the same force, up and normal to the face, and the material's at the depth the probe
// reached (a static solve with a tool held at the probe's final position, which meets the contact constraint
// exactly): the probe is a proxy kept on the surface by the contact's multipliers.
#include <pointhaptics/haptics/devices/virtual_device.hpp>
#include <pointhaptics/session/interactive.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/session/scene_builder.hpp>
#include <pointhaptics/session/scene_session.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace pointhaptics {
namespace {

constexpr double R = 0.01;

Scene block_scene(const std::string& solver) {
  Scene s = parse_scene(R"(
[object]
shape = "box"
size = [0.04, 0.02, 0.04]
origin = [-0.02, 0.0, -0.02]
spacing = 0.0025
[material]
model = "neo_hookean"
young = 1e5
poisson = 0.3
density = 1000.0
damping = 50.0
[[fixed]]
box = { min = [-1.0, -1.0, -1.0], max = [1.0, 0.0, 1.0] }
[solver]
kind = "explicit"
dt = 1e-3
)");
  s.solver.kind = solver == "implicit" ? SolverKind::IMPLICIT
                  : solver == "static" ? SolverKind::STATIC
                                       : SolverKind::EXPLICIT;
  return s;
}

// the block simulated on one thread, with its surface
struct Block {
  Scene scene;
  Simulation sim;
  ObjectSurface surface;
  explicit Block(const std::string& solver)
      : scene(block_scene(solver)),
        sim(build_scene_model(scene), scene.solver, 1),
        surface(build_object_surface(scene, sim.model())) {}
};

// a probe of radius R on the block's surface, the device's origin 2 R above its top face, in simulated time
InteractiveOptions probe_options(const ObjectSurface& surface, double duration) {
  InteractiveOptions o;
  o.probe.radius = R;
  o.mapping.origin = Vec3(0, 0.02 + 2 * R, 0);
  o.duration = duration;
  o.real_time = false;
  o.surface = std::make_shared<const ObjectSurface>(surface);
  o.probe.object_stiffness = true;
  return o;
}

struct Press {
  Vec3 probe;  // the probe's final position
  Vec3 felt;   // the last force rendered to the device
  int contacts = 0;
  double penetration = 0;    // the deepest surface vertex inside the probe at the end, m
  long long selections = 0;  // of the active set, with levels of detail
};

// the probe's centre starts 2 R above the top face and goes down 2 R + 1.5 mm over 0.4 s, then holds
// With levels of detail (`lod`) the active set is selected around the top face's centre and follows the probe.
Press press(const std::string& solver, bool lod = false) {
  Block block(solver);
  Simulation& sim = block.sim;
  const ObjectSurface& surface = block.surface;
  if (lod) {
    LodParams params;
    params.levels = {{3.0, 6}};
    sim.enable_lod(params, Vec3(0, 0.02, 0));
  }
  VirtualDevice device(Trajectory({{0.0, Vec3::Zero(), false},
                                   {0.4, Vec3(0, -2 * R - 0.0015, 0), false},
                                   {0.6, Vec3(0, -2 * R - 0.0015, 0), false}}),
                       known_device_specs("touch"));
  InteractiveOptions o = probe_options(surface, 0.6);
  Press p;
  o.after_step = [&](long long) {
    p.probe = sim.probe()->probe();
    p.contacts = sim.probe()->contact_model().contacts;
    ASSERT_TRUE(sim.probe()->on_surface());
    p.penetration = sim.probe()->surface_contact()->last_load().penetration;
  };
  const InteractiveResult r = run_interactive(sim, device, o);
  EXPECT_FALSE(sim.diagnostics().failed) << sim.diagnostics().failure;
  p.felt = r.log.back().force;
  if (lod) {
    EXPECT_LT(sim.simulated_model().n_points, sim.model().n_points);
    p.selections = sim.summary().lod.selections;
  }
  return p;
}

// the force of the material with the probe held at `probe`, the contact met exactly
double static_force(const Vec3& probe) {
  Block block("static");
  Simulation& sim = block.sim;
  const ObjectSurface& surface = block.surface;
  sim.hold_tool(ToolShape{ToolKind::SPHERE, R, 0}, ToolPose{probe, Eigen::Quaterniond::Identity()}, surface.mesh,
                surface.map);
  const StepReport& report = sim.step();
  EXPECT_NE(report.status, StepStatus::FAILED) << report.failure;
  return sim.summary().tool.force.y();
}

TEST(ProbeOnSurface, ASlowPressRendersTheMaterialsForceInBothSolversWithTheProbeOnTheSurface) {
  const Press explicit_press = press("explicit"), implicit_press = press("implicit");
  for (const Press& p : {explicit_press, implicit_press}) {
    ASSERT_GT(p.contacts, 0);
    const double depth = 0.02 + R - p.probe.y();  // of the probe below the undeformed top face
    EXPECT_GT(depth, 0.001);
    EXPECT_GT(p.felt.y(), 0.0);
    EXPECT_LT(std::hypot(p.felt.x(), p.felt.z()), 0.05 * p.felt.y());
    // the proxy: the surface touches the probe (issue 16: no penetration beyond 1% of the depth)
    EXPECT_LT(p.penetration, 0.01 * depth);
  }
  EXPECT_NEAR(explicit_press.felt.y(), implicit_press.felt.y(), 0.01 * implicit_press.felt.y());
  // the material's force with the probe there and the contact met exactly (a static solve): the penalty
  // alone rendered 0.78 of it, the proxy's multipliers 0.999 (docs/haptics.md)
  const double reference = static_force(implicit_press.probe);
  std::printf("felt: explicit %.4f N, implicit %.4f N; the material's %.4f N (%.4f); penetration %.3g m of %.3g m\n",
              explicit_press.felt.y(), implicit_press.felt.y(), reference, implicit_press.felt.y() / reference,
              implicit_press.penetration, 0.02 + R - implicit_press.probe.y());
  EXPECT_NEAR(implicit_press.felt.y(), reference, 0.02 * reference);
}

// With levels of detail the probe touches the part of the surface the active set carries (issue 16, item
// 2): the same press renders the full model's force, on the surface.
TEST(ProbeOnSurface, WithLevelsOfDetailTheProbeTouchesTheActiveSetsSurface) {
  const Press full = press("explicit"), lod = press("explicit", true);
  const double depth = 0.02 + R - lod.probe.y();
  std::printf("levels of detail: felt %.4f N (full model %.4f N), penetration %.3g m of %.3g m, %lld selections\n",
              lod.felt.y(), full.felt.y(), lod.penetration, depth, lod.selections);
  ASSERT_GT(lod.contacts, 0);
  EXPECT_GE(lod.selections, 1);
  EXPECT_LT(lod.penetration, 0.01 * depth);
  EXPECT_NEAR(lod.felt.y(), full.felt.y(), 0.03 * full.felt.y());
}

// A capsule posed by the device (issue 16, item 1): 20 mm long, 5 mm in radius, lying along x and tilted
// by `tilt` (its +x end lower for tilt > 0), pressed in until its lowest point is 1 mm below the top face.
// The end pressed deeper pushes back harder: the torque about the tool's centre turns it back level. With a
// device that renders torque (max_torque > 0, N m), `rendered` gets the last torque commanded to it.
ToolSummary press_capsule(double tilt, double max_torque = 0, Vec3* rendered = nullptr) {
  Block block("explicit");
  Simulation& sim = block.sim;
  const ObjectSurface& surface = block.surface;
  const double radius = 0.005, length = 0.02;
  const double centre = 0.02 - 0.001 + radius + 0.5 * length * std::sin(std::abs(tilt));
  VirtualDevice device(Trajectory({{0.0, Vec3::Zero(), false},
                                   {0.3, Vec3(0, centre - (0.02 + 2 * R), 0), false},
                                   {0.5, Vec3(0, centre - (0.02 + 2 * R), 0), false}}),
                       [&] {
                         DeviceSpecs specs = known_device_specs("touch");
                         specs.max_torque = max_torque;
                         return specs;
                       }());
  InteractiveOptions o = probe_options(surface, 0.5);
  o.probe.radius = radius;
  o.probe.length = length;
  // the local axis z turned onto x, then tilted about z
  o.probe.orientation = Eigen::AngleAxisd(-tilt, Vec3::UnitZ()) * Eigen::AngleAxisd(0.5 * M_PI, Vec3::UnitY());
  ToolSummary tool;
  o.after_step = [&](long long) { tool = sim.tool_summary(); };
  const InteractiveResult r = run_interactive(sim, device, o);
  EXPECT_FALSE(sim.diagnostics().failed) << sim.diagnostics().failure;
  if (rendered) *rendered = r.log.back().torque;
  return tool;
}

TEST(ProbeOnSurface, ATiltedCapsulePressesWithItsLowerEndAndFeelsTheTorque) {
  const ToolSummary level = press_capsule(0.0), right = press_capsule(0.15), left = press_capsule(-0.15);
  for (const ToolSummary* t : {&level, &right, &left}) {
    std::printf(
        "%s at y = %.5f m: force (%.4f, %.4f, %.4f) N, torque (%.3g, %.3g, %.3g) N m, %d contacts, %.3g m inside\n",
        t->kind.c_str(), t->position.y(), t->force.x(), t->force.y(), t->force.z(), t->torque.x(), t->torque.y(),
        t->torque.z(), t->contacts, t->penetration);
    EXPECT_EQ(t->kind, "capsule");
    EXPECT_GT(t->contacts, 0);
    EXPECT_GT(t->force.y(), 0.05);
    EXPECT_LT(t->penetration, 0.01 * 0.001);  // of the 1 mm it was pressed in
  }
  // level: the force through its centre; tilted: its lower end's push turns it back level, each way
  const double lever = 0.5 * 0.02 * right.force.y();  // the torque were all the force at the lower end
  EXPECT_LT(std::abs(level.torque.z()), 0.02 * lever);
  EXPECT_GT(right.torque.z(), 0.2 * lever);
  EXPECT_LT(left.torque.z(), -0.2 * lever);
  EXPECT_NEAR(right.torque.z(), -left.torque.z(), 0.05 * right.torque.z());
  // the hand feels it on a device that renders torque (issue 16, item 1), and nothing on the Touch
  Vec3 rendered = Vec3::Constant(NAN), on_touch = Vec3::Constant(NAN);
  const ToolSummary six_dof = press_capsule(0.15, 0.1, &rendered);
  press_capsule(0.15, 0.0, &on_touch);
  std::printf("rendered torque (%.3g, %.3g, %.3g) N m, the tool's (%.3g, %.3g, %.3g) N m\n", rendered.x(), rendered.y(),
              rendered.z(), six_dof.torque.x(), six_dof.torque.y(), six_dof.torque.z());
  EXPECT_NEAR(rendered.z(), six_dof.torque.z(), 0.05 * six_dof.torque.z());
  EXPECT_GT(rendered.z(), 0.2 * lever);
  EXPECT_EQ(on_touch.norm(), 0.0);
}

// Pressed in, then pushed up and down by 0.5 mm and dragged sideways: the local model the haptic side renders
// between updates takes its stiffness from the object's compliance (issue 16, item 4), so it predicts the
// next update's force better than the contact's own stiffness (the held object's) or no stiffness at all.
TEST(ProbeOnSurface, TheLocalModelsStiffnessIsTheObjectsAndPredictsTheNextUpdate) {
  for (const std::string solver : {"explicit", "implicit"}) {
    Block block(solver);
    Simulation& sim = block.sim;
    const ObjectSurface& surface = block.surface;
    const double down = -2 * R - 0.0015;
    VirtualDevice device(Trajectory({{0.0, Vec3::Zero(), false},
                                     {0.3, Vec3(0, down, 0), false},
                                     {0.4, Vec3(0, down + 0.0005, 0), false},
                                     {0.5, Vec3(0, down - 0.0005, 0), false},
                                     {0.6, Vec3(0, down, 0), false},
                                     {0.8, Vec3(0.004, down, 0), false}}),
                         known_device_specs("touch"));
    InteractiveOptions o = probe_options(surface, 0.8);
    Mat3 K = Mat3::Zero(), held = Mat3::Zero();
    o.after_step = [&](long long) {
      K = sim.probe()->contact_model().K;
      held = sim.probe()->held_stiffness();
    };
    const InteractiveResult r = run_interactive(sim, device, o);
    ASSERT_FALSE(sim.diagnostics().failed) << sim.diagnostics().failure;
    const LocalModelSummary& m = r.local_model;
    std::printf(
        "%s: %lld updates, mean force %.4f N; stray mean / max: rendered %.3g / %.3g N, hold %.3g / %.3g N, held object "
        "%.3g / %.3g N; K_yy %.4g N/m, held %.4g N/m\n",
        solver.c_str(), m.updates, m.force_mean_n, m.rendered_mean_n, m.rendered_max_n, m.hold_mean_n, m.hold_max_n,
        m.held_object_mean_n, m.held_object_max_n, K(1, 1), held(1, 1));
    EXPECT_GT(m.updates, 300);
    EXPECT_LT(m.rendered_mean_n, m.held_object_mean_n);
    EXPECT_LT(m.rendered_mean_n, m.hold_mean_n);
    // softer than the contact alone, and never pulling
    EXPECT_LT(K(1, 1), 0.0);
    EXPECT_GT(K(1, 1), held(1, 1));
    EXPECT_LE(Eigen::SelfAdjointEigenSolver<Mat3>(K).eigenvalues().maxCoeff(), 1e-9 * std::abs(K(1, 1)));
  }
}

// Friction on a device's probe (issue 16, item 3): pressed into the block, then the device moved sideways,
// so that the hand pushes along a line at an angle to the face's normal, as a tool resting on a slope. Inside
// Coulomb's cone the probe stays where it is (it sticks, the hand feeling the friction that holds it);
// without friction it follows the hand; dragged on, it slides with friction mu times the pressure.
struct Slide {
  double probe_x = 0, device_x = 0;  // where the probe and the device ended, m
  Vec3 felt;                         // the last force rendered, N
  double sliding_ratio = 0;          // friction over pressure on the tool, mean over the steps after t = 0.6 s
};

// down into the block by 0.3 s, held, then from 0.4 s moved sideways by `sideways` over `over` seconds, held
Slide slide(const std::string& solver, double friction, double sideways, double over, double duration) {
  Block block(solver);
  Simulation& sim = block.sim;
  const ObjectSurface& surface = block.surface;
  const double down = -2 * R - 0.0015;
  VirtualDevice device(Trajectory({{0.0, Vec3::Zero(), false},
                                   {0.3, Vec3(0, down, 0), false},
                                   {0.4, Vec3(0, down, 0), false},
                                   {0.4 + over, Vec3(sideways, down, 0), false},
                                   {std::max(duration, 0.4 + over) + 0.1, Vec3(sideways, down, 0), false}}),
                       known_device_specs("touch"));
  InteractiveOptions o = probe_options(surface, duration);
  o.probe.friction = friction;
  Slide out;
  double ratio_sum = 0;
  int ratios = 0;
  o.after_step = [&](long long) {
    out.probe_x = sim.probe()->probe().x();
    const ToolLoad& load = sim.probe()->surface_contact()->last_load();
    if (sim.state().time > 0.6) {
      ratio_sum += load.friction.norm() / (load.force - load.friction).norm();
      ++ratios;
    }
  };
  const InteractiveResult r = run_interactive(sim, device, o);
  EXPECT_FALSE(sim.diagnostics().failed) << sim.diagnostics().failure;
  out.felt = r.log.back().force;
  out.device_x = r.log.back().position.x();
  out.sliding_ratio = ratios ? ratio_sum / ratios : 0.0;
  return out;
}

TEST(ProbeOnSurface, WithFrictionTheProbeRestsWhereTheHandPushesInsideTheConeAndSlidesBeyondIt) {
  // the coupling (200 N/m for the touch) pulls sideways by about 0.2 N per mm of the probe behind the device,
  // against about 1.2 N of pressure: 1 mm is well inside the cone of mu = 0.3
  const double mu = 0.3;
  const Slide frictionless = slide("explicit", 0.0, 0.001, 0.1, 0.7);
  EXPECT_NEAR(frictionless.probe_x, frictionless.device_x, 0.1e-3);
  EXPECT_LT(std::abs(frictionless.felt.x()), 0.02 * frictionless.felt.y());
  for (const std::string solver : {"explicit", "implicit"}) {
    const Slide rests = slide(solver, mu, 0.001, 0.1, 0.7);
    std::printf("%s, resting: probe at %.3f mm, device at %.3f mm, felt (%.4f, %.4f) N\n", solver.c_str(),
                1e3 * rests.probe_x, 1e3 * rests.device_x, rests.felt.x(), rests.felt.y());
    // it stays (what moves is mostly the block's shear under it), and the hand feels what holds it
    EXPECT_LT(std::abs(rests.probe_x), 0.3 * rests.device_x);
    EXPECT_LT(rests.felt.x(), -0.05 * rests.felt.y());
    EXPECT_LT(std::abs(rests.felt.x()), mu * rests.felt.y());
  }
  // dragged 6 mm over 0.4 s: it slides behind the hand with friction mu x pressure
  const Slide slides = slide("explicit", mu, 0.006, 0.4, 0.8);
  std::printf("sliding: probe at %.3f mm, device at %.3f mm, felt (%.4f, %.4f) N, friction / pressure %.4f\n",
              1e3 * slides.probe_x, 1e3 * slides.device_x, slides.felt.x(), slides.felt.y(), slides.sliding_ratio);
  EXPECT_GT(slides.probe_x, 0.5 * slides.device_x);
  EXPECT_NEAR(slides.sliding_ratio, mu, 0.05 * mu);
}

// What the probe did on the soft dome (the test below), step by step.
struct DomeRun {
  long long steps = 0, inside = 0;  // steps, and those at whose end the probe's centre is inside the surface
  double deepest = 0;               // the probe's centre's furthest inside the surface at a step's end, m
  double behind = 0;                // the probe's furthest behind the hand across the dome (x) as it slides, m
  double radius = 0;
  Vec3 probe = Vec3::Constant(NAN);  // at the end
};

DomeRun press_and_slide_on_the_soft_dome(bool levels_of_detail) {
  Scene scene = read_scene_file(PH_SCENES "/half_sphere_lod.toml");
  if (!levels_of_detail) scene.lod = LodSpec{};
  SessionOptions options;
  options.threads = 1;
  SceneSession session = open_scene(std::move(scene), options);
  Simulation& sim = *session.simulation;
  InteractiveOptions o = session.interactive;
  o.real_time = false;
  // the contact's own behaviour, as docs/haptics.md measured it: the passivity controller's damping of the
  // hand (it acts on about half the ticks of this slide) moves this chaotic run's counts
  o.rules.passivity_control = false;
  DomeRun run;
  EXPECT_TRUE(o.surface);
  run.radius = o.probe.radius;
  o.after_step = [&](long long) {  // (the probe is detached when the run ends)
    ++run.steps;
    ASSERT_TRUE(sim.probe() && sim.probe()->surface_contact());
    run.probe = sim.probe()->probe();
    if (sim.time() > 0.75 && sim.time() < 1.5)
      run.behind = std::max(run.behind, sim.probe()->device().x() - run.probe.x());
    const std::optional<SurfaceSide> side = sim.probe()->surface_contact()->side_of(run.probe, 2 * run.radius);
    if (!side || !side->sure || side->distance >= 0) return;
    ++run.inside;
    run.deepest = std::min(run.deepest, side->distance);
  };
  run_interactive(sim, *session.device, o);
  EXPECT_FALSE(sim.diagnostics().failed) << sim.diagnostics().failure;
  std::printf(
      "soft dome%s: the probe's centre inside the surface at %lld of %lld steps' ends, at most %.2f mm; ends at (%.1f, %.1f, %.1f) mm; "
      "at most %.1f mm behind the hand as it slides\n",
      levels_of_detail ? " with levels of detail" : "", run.inside, run.steps, -1e3 * run.deepest, 1e3 * run.probe.x(),
      1e3 * run.probe.y(), 1e3 * run.probe.z(), 1e3 * run.behind);
  return run;
}

// The soft, coarse dome of scenes/half_sphere_lod.toml without [lod] (E = 1e4 Pa, spacing 4 mm, a 6 mm probe:
// 1.5 spacings per radius) pressed 8 mm and slid 2 cm aside. The surface, pushed apart by the probe, flowed
// over its centre within a step at 1.7 s, and the probe, inside with no vertex in it, sank through and stayed
// under the dome (5.5 mm inside at the end). Now it is put back on the surface: its centre ends outside, and
// is found inside at the end of a step only as the surface flows over it (then put back at the next).
TEST(ProbeOnSurface, OnASoftCoarseDomeTheProbeStaysOnTheSurfaceAsTheHandSlidesAside) {
  const DomeRun run = press_and_slide_on_the_soft_dome(false);
  EXPECT_EQ(run.steps, 2000);
  // 112 since the coupling's damper stopped differentiating the contact model's jumps (85 before that, 294
  // before the probe was put back): this chaotic run's count moves with any change to the loop
  EXPECT_LT(run.inside, run.steps / 15);
  EXPECT_GT(run.deepest, -0.5 * run.radius);  // 1.7 mm (6.1 mm before)
  // and the probe followed the hand aside (2 cm) on the dome's top (its top at y = 5 cm), as it slid: held
  // where the god-object refused every move deeper (a vertex 1.6-1.9 mm inside it), it stayed at the top
  // until the hand was 18 mm aside; now a refused move slides across the contact's force
  EXPECT_LT(run.behind, 1.5 * run.radius);  // 6.9 mm (17 mm before)
  EXPECT_GT(run.probe.x(), 0.01);
  EXPECT_GT(run.probe.y(), 0.04);
}

// The same with the scene's levels of detail: the active set's part of the surface pressed with a penalty
// lowered uniformly until its stiffest point (a thinned band's, carrying the vertices of the points it absorbed)
// met the cap, 12x softer than the whole surface's; the probe sank 5 mm into the surface and stayed at x = 5.4 mm
// while the hand went to 20 mm. Now the part presses as the whole surface does, point by point.
TEST(ProbeOnSurface, WithLevelsOfDetailTheProbeFollowsTheHandAsOnTheWholeDome) {
  const DomeRun run = press_and_slide_on_the_soft_dome(true);
  EXPECT_EQ(run.steps, 2000);
  EXPECT_LT(run.behind, 1.5 * run.radius);  // 7.8 mm (16.7 mm before)
  EXPECT_GT(run.probe.x(), 0.015);          // 21.5 mm (6.5 mm before)
  EXPECT_GT(run.probe.y(), 0.04);
  // its centre found inside at the end of a step as the surface flows over it (177 steps, at most 0.69 mm;
  // before, never: the surface sank into the probe instead)
  EXPECT_LT(run.inside, run.steps / 10);
  EXPECT_GT(run.deepest, -0.25 * run.radius);
}

}  // namespace
}  // namespace pointhaptics
