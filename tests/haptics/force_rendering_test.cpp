// Tests for haptics/device (known specs), haptics/exchange (the triple buffer) and haptics/force_rendering
// (coupling budget, engage rule, ramp, magnitude clamp, rate bound, passivity observer).
#include <pointhaptics/haptics/device.hpp>
#include <pointhaptics/haptics/exchange.hpp>
#include <pointhaptics/haptics/force_rendering.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

namespace pointhaptics {
namespace {

TEST(DeviceSpecs, KnownDevicesAndANamedErrorForOthers) {
  EXPECT_DOUBLE_EQ(known_device_specs("touch").max_force, 3.3);
  EXPECT_DOUBLE_EQ(known_device_specs("touch").max_stiffness, 400.0);
  EXPECT_DOUBLE_EQ(known_device_specs("omni").max_stiffness, 700.0);
  EXPECT_DOUBLE_EQ(known_device_specs("falcon").max_force, 8.0);
  try {
    known_device_specs("phantom-9000");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown device \"phantom-9000\""), std::string::npos);
  }
}

TEST(TripleBuffer, ConsumerSeesTheLatestPublishedValueOnce) {
  TripleBuffer<int> buffer(-1);
  EXPECT_FALSE(buffer.update());
  EXPECT_EQ(buffer.front(), -1);
  buffer.back() = 1;
  buffer.publish();
  buffer.back() = 2;
  buffer.publish();
  EXPECT_TRUE(buffer.update());
  EXPECT_EQ(buffer.front(), 2);  // the latest, 1 was overwritten
  EXPECT_FALSE(buffer.update());
  EXPECT_EQ(buffer.front(), 2);
  buffer.back() = 3;
  buffer.publish();
  EXPECT_TRUE(buffer.update());
  EXPECT_EQ(buffer.front(), 3);
}

// A value that is torn if it is read while being written.
struct Frame {
  long long id = 0;
  double data[32] = {};
};

TEST(TripleBuffer, TwoThreadsNeverSeeATornOrOlderValue) {
  TripleBuffer<Frame> buffer;
  std::atomic<bool> done{false};
  const long long frames = 200000;
  std::thread producer([&] {
    for (long long id = 1; id <= frames; ++id) {
      Frame& f = buffer.back();
      f.id = id;
      for (double& x : f.data) x = static_cast<double>(id);
      buffer.publish();
    }
    done = true;
  });
  long long last = 0, torn = 0, backwards = 0, seen = 0;
  for (;;) {
    const bool finished = done.load();  // read before update(): every publish is then visible to it
    if (buffer.update()) {
      const Frame& f = buffer.front();
      for (double x : f.data) torn += x != static_cast<double>(f.id);
      backwards += f.id < last;
      last = f.id;
      ++seen;
    } else if (finished) {
      break;
    }
  }
  producer.join();
  EXPECT_EQ(torn, 0);
  EXPECT_EQ(backwards, 0);
  EXPECT_EQ(buffer.front().id, frames);  // the last value always arrives
  EXPECT_GT(seen, 0);
}

TEST(CouplingBudget, FeltStiffnessStaysBelowTheDevicesStableMaximum) {
  const DeviceSpecs touch = known_device_specs("touch");
  for (double scale : {0.5, 1.0, 4.0}) {
    const CouplingGains g = coupling_budget(touch, scale, 0.5);
    EXPECT_NEAR(g.stiffness * scale, 0.5 * touch.max_stiffness, 1e-12);
    EXPECT_NEAR(g.damping * scale, 0.5 * touch.max_damping, 1e-12);
  }
  EXPECT_THROW(coupling_budget(touch, 0.0), Error);
  EXPECT_THROW(coupling_budget(touch, 1.0, 1.5), Error);
}

TEST(ForceRenderer, EngagesOnlyOnceTheRequestIsSmallThenRampsIn) {
  ForceRules rules;
  rules.ramp_time = 0.1;
  rules.max_change = 100;  // not under test here
  ForceRenderer r(known_device_specs("touch"), rules);
  const double dt = 1e-3;
  // the device starts inside an object: 2 N requested, nothing rendered
  for (int k = 0; k < 50; ++k) EXPECT_EQ(r.render(Vec3(0, 2, 0), Vec3::Zero(), dt), Vec3::Zero());
  EXPECT_FALSE(r.engaged());
  // the request drops below the threshold: engaged, then ramped
  r.render(Vec3(0, 0.05, 0), Vec3::Zero(), dt);
  EXPECT_TRUE(r.engaged());
  const Vec3 early = r.render(Vec3(0, 2, 0), Vec3::Zero(), dt);
  EXPECT_NEAR(early.y(), 2.0 * 2e-3 / 0.1, 1e-12);
  for (int k = 0; k < 200; ++k) r.render(Vec3(0, 2, 0), Vec3::Zero(), dt);
  EXPECT_NEAR(r.last_force().y(), 2.0, 1e-12);
}

TEST(ForceRenderer, ClampsTheMagnitudeNotTheComponentsAndBoundsTheChange) {
  ForceRules rules;
  rules.ramp_time = 0;
  rules.max_change = 0.2;
  const DeviceSpecs touch = known_device_specs("touch");
  ForceRenderer r(touch, rules);
  r.render(Vec3::Zero(), Vec3::Zero(), 1e-3);  // engage
  const Vec3 request(30, -40, 0);              // 50 N along (0.6, -0.8, 0)
  Vec3 f = Vec3::Zero();
  for (int k = 0; k < 100; ++k) {
    const Vec3 next = r.render(request, Vec3::Zero(), 1e-3);
    EXPECT_LE((next - f).norm(), 0.2 + 1e-12);
    EXPECT_LE(next.norm(), touch.max_force + 1e-12);
    f = next;
  }
  EXPECT_NEAR(f.norm(), touch.max_force, 1e-12);
  EXPECT_NEAR(f.x() / f.norm(), 0.6, 1e-12);  // direction kept
  EXPECT_EQ(r.render(Vec3(NAN, 0, 0), Vec3::Zero(), 1e-3).allFinite(), true);
}

TEST(ForceRenderer, PassivityObserverSeesASpringAsPassiveAndAnActiveForceAsNot) {
  ForceRules rules;
  rules.ramp_time = 0;
  rules.max_change = 100;
  rules.passivity_control = false;  // the observer alone
  const double k = 200, dt = 1e-3;
  ForceRenderer spring(known_device_specs("touch"), rules), active(known_device_specs("touch"), rules);
  active.render(Vec3::Zero(), Vec3::Zero(), dt);  // engage
  // the hand goes into a wall spring and back out along the same path
  for (int t = 0; t < 2000; ++t) {
    const double x = 0.005 * std::sin(M_PI * t / 1000.0);  // in and out
    const double v = 0.005 * M_PI * std::cos(M_PI * t / 1000.0);
    spring.render(Vec3(-k * std::max(x, 0.0), 0, 0), Vec3(v, 0, 0), dt);
    active.render(Vec3(0.5, 0, 0), Vec3(v > 0 ? 0.01 : 0.0, 0, 0), dt);  // pushes along the motion
  }
  EXPECT_GT(spring.min_observed_energy(), -1e-5);
  EXPECT_NEAR(spring.observed_energy(), 0.0, 1e-5);
  EXPECT_LT(active.observed_energy(), -1e-4);
}

// The passivity controller (Hannaford & Ryu): a force that pushes the hand along its motion, after the hand
// put some energy in, is let through until that energy is given back, then damped so that the observer never
// goes below zero (where the change per tick is not bounded); the damping force never exceeds the force's own
// part along the velocity plus the device's max damping times the speed. A spring stays untouched.
TEST(ForceRenderer, PassivityControllerKeepsTheObserverAtOrAboveZero) {
  ForceRules rules;
  rules.ramp_time = 0;
  rules.max_change = 100;
  rules.passivity_speed =
      0;  // the force's part along the velocity taken out at any speed (the default fades it, below)
  const DeviceSpecs touch = known_device_specs("touch");
  const double dt = 1e-3;
  ForceRenderer active(touch, rules), spring(touch, rules);
  active.render(Vec3::Zero(), Vec3::Zero(), dt);  // engage
  spring.render(Vec3::Zero(), Vec3::Zero(), dt);
  // 0.5 N against a hand moving at 0.02 m/s for 0.1 s: 1 mJ absorbed
  for (int t = 0; t < 100; ++t) EXPECT_EQ(active.render(Vec3(-0.5, 0, 0), Vec3(0.02, 0, 0), dt), Vec3(-0.5, 0, 0));
  EXPECT_NEAR(active.observed_energy(), 1e-3, 1e-12);
  EXPECT_EQ(active.controller_ticks(), 0);
  // then 0.5 N along it: 1e-5 J a tick, rendered untouched for 100 ticks, damped after
  const Vec3 v(0.02, 0.01, 0);
  double least = 1;
  for (int t = 0; t < 400; ++t) {
    const Vec3 f = active.render(Vec3(0.5, 0, 0), v, dt);
    if (t < 99) {
      EXPECT_EQ(f, Vec3(0.5, 0, 0)) << t;
    }
    const Vec3 damper = f - Vec3(0.5, 0, 0);
    EXPECT_LE(damper.norm(), Vec3(0.5, 0, 0).dot(v) / v.norm() + touch.max_damping * v.norm() + 1e-12) << t;
    EXPECT_LE(damper.dot(v), 1e-15) << t;  // against the motion
    least = std::min(least, active.observed_energy());
  }
  EXPECT_GT(least, -1e-12);
  EXPECT_GT(active.controller_ticks(), 290);
  EXPECT_NEAR(active.controller_dissipated(), 300 * 0.5 * 0.02 * dt + active.observed_energy(),
              1e-9);  // what the force gave beyond 1 mJ
  // a spring the hand goes into and back out of along the same path needs no control
  for (int t = 0; t < 2000; ++t) {
    const double x = 0.005 * std::sin(M_PI * t / 1000.0), speed = 0.005 * M_PI * std::cos(M_PI * t / 1000.0);
    const Vec3 f = spring.render(Vec3(-200 * std::max(x, 0.0), 0, 0), Vec3(speed, 0, 0), dt);
    EXPECT_NEAR(f.x(), -200 * std::max(x, 0.0), 1e-3) << t;
  }
  EXPECT_LT(spring.controller_dissipated(), 1e-6);
  // the rules bound the commanded force's change per tick, the damper's included: the controller then takes a
  // few ticks to catch up, and the observer dips below zero by no more than what those ticks let through
  ForceRules bounded = rules;
  bounded.max_change = 0.2;
  ForceRenderer gradual(touch, bounded);
  gradual.render(Vec3::Zero(), Vec3::Zero(), dt);
  Vec3 last = Vec3::Zero();
  for (int t = 0; t < 400; ++t) {
    const Vec3 f = gradual.render(Vec3(0.5, 0, 0), v, dt);
    EXPECT_LE((f - last).norm(), 0.2 + 1e-12) << t;
    last = f;
  }
  EXPECT_GT(gradual.controller_ticks(), 390);
  EXPECT_LT(gradual.min_observed_energy(), 0.0);
  EXPECT_GT(gradual.min_observed_energy(), -3 * 0.5 * v.norm() * dt);  // under three ticks of the force's work
  // a device without damping still has the force's giving part taken out: the observer stays at zero
  DeviceSpecs undamped = touch;
  undamped.max_damping = 0;
  ForceRenderer bare(undamped, rules);
  bare.render(Vec3::Zero(), Vec3::Zero(), dt);
  for (int t = 0; t < 100; ++t) EXPECT_NEAR(bare.render(Vec3(0.5, 0.3, 0), v, dt).dot(v), 0.0, 1e-15);
  EXPECT_GT(bare.min_observed_energy(), -1e-12);
  // a hand nearly still (1 mm/s) whose velocity turns from tick to tick: taking out the force's part along
  // each tick's direction makes the force jump; with the default passivity_speed (10 mm/s) the controller
  // takes out little more than the device's damping, and the force stays within 10 mN of the request
  ForceRules faded = rules;
  faded.passivity_speed = ForceRules{}.passivity_speed;
  ForceRenderer smooth(touch, faded), sharp(touch, rules);
  smooth.render(Vec3::Zero(), Vec3::Zero(), dt);
  sharp.render(Vec3::Zero(), Vec3::Zero(), dt);
  double worst_smooth = 0, worst_sharp = 0;
  const Vec3 request(0.5, 0, 0);
  for (int t = 0; t < 200; ++t) {
    const Vec3 wandering = 1e-3 * Vec3(std::cos(2.4 * t), std::sin(2.4 * t), 0);
    worst_smooth = std::max(worst_smooth, (smooth.render(request, wandering, dt) - request).norm());
    worst_sharp = std::max(worst_sharp, (sharp.render(request, wandering, dt) - request).norm());
  }
  EXPECT_GT(smooth.controller_ticks(), 0);
  EXPECT_LT(worst_smooth, 0.01);
  EXPECT_GT(worst_sharp, 0.3);
}

}  // namespace
}  // namespace pointhaptics
