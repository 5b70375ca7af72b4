// Tests for haptics/haptic_loop: a tick reads the device, puts the probe where the coupling spring balances
// the published contact model, renders the coupling force within the device's limit, publishes the frame and
// logs the tick; a failed device stops the loop with zero force.
#include <pointhaptics/haptics/haptic_loop.hpp>

#include <pointhaptics/haptics/coupling.hpp>
#include <pointhaptics/haptics/devices/virtual_device.hpp>

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

// a device held still at its origin (no hand dynamics to speak of)
VirtualDevice still_device() {
  return VirtualDevice(Trajectory({{0.0, Vec3::Zero(), false}, {10.0, Vec3::Zero(), false}}),
                       known_device_specs("touch"));
}

TEST(HapticLoop, WithoutContactTheProbeIsTheDevicePointAndNoForceIsFelt) {
  VirtualDevice device = still_device();
  WorkspaceMapping mapping;
  mapping.origin = Vec3(0.1, 0.2, 0.3);
  HapticLoop loop(device, mapping, CouplingGains{500, 1}, {}, 1000.0, 16);
  ASSERT_TRUE(loop.tick(1e-3, 1e-3));
  loop.frames().update();
  const HapticFrame& f = loop.frames().front();
  EXPECT_LE((f.probe - mapping.origin).norm(), 1e-12);
  EXPECT_LE((f.device - mapping.origin).norm(), 1e-12);
  EXPECT_LE(f.force.norm(), 1e-12);
  EXPECT_EQ(f.tick, 1);
  int logged = 0;
  loop.take_log([&](const HapticLogRow& row) {
    EXPECT_DOUBLE_EQ(row.t, 1e-3);
    ++logged;
  });
  EXPECT_EQ(logged, 1);
}

TEST(HapticLoop, TheProbeBalancesThePublishedContactModel) {
  VirtualDevice device = still_device();
  WorkspaceMapping mapping;  // the device point is the scene origin
  const double k = 500;
  // the contact model below appears at once, pushing a hand that yields: it gives the hand energy it never
  // took, which the passivity controller would take out; the balance is what this test checks
  ForceRules rules;
  rules.passivity_control = false;
  HapticLoop loop(device, mapping, CouplingGains{k, 0}, rules, 1000.0);
  // the object pushes up with 0.5 N and 300 N/m near p0 = 1 mm below the device point: the probe settles
  // about 0.25 mm above the device point, (0.5 - 0.3) N / (500 + 300) N/m
  ContactModel m;
  m.p0 = Vec3(0, -1e-3, 0);
  m.f0 = Vec3(0, 0.5, 0);
  m.K = -300 * Mat3::Identity();
  m.contacts = 3;
  // the renderer engages while the request is small (before contact), then the contact comes; the force
  // ramps in over a few ticks (ForceRenderer), the probe is placed at once
  for (int k_tick = 1; k_tick <= 10; ++k_tick) ASSERT_TRUE(loop.tick(k_tick * 1e-3, 1e-3));
  loop.contact_models().back() = m;
  loop.contact_models().publish();
  for (int k_tick = 11; k_tick <= 200; ++k_tick) ASSERT_TRUE(loop.tick(k_tick * 1e-3, 1e-3));
  loop.frames().update();
  const HapticFrame& f = loop.frames().front();
  const Vec3 d = f.device;
  const Vec3 p = f.probe;
  // k (d - p) + f0 + K (p - p0) = 0
  EXPECT_LE((k * (d - p) + m.f0 + m.K * (p - m.p0)).norm(), 1e-9);
  EXPECT_LE((p - coupled_probe(m, d, k, device.specs().max_force)).norm(), 1e-12);
  EXPECT_NEAR(p.y() - d.y(), (0.5 - 300 * (d.y() - m.p0.y())) / 800, 1e-12);  // the hand yields a little: d moves
  // the hand feels the coupling spring, pulling it toward the probe: up, as the object pushes
  EXPECT_GT(f.force.y(), 0.0);
  EXPECT_LE(f.force.norm(), device.specs().max_force + 1e-12);
}

}  // namespace
}  // namespace pointhaptics

namespace pointhaptics {
namespace {

// A new contact model from the simulation moves the probe at once. The coupling's damper acts on the probe's
// motion under one model as the device moves, not on that jump: differentiated, the jump was a force impulse
// b dp/dt at every simulation step (a buzz of 150-500 Hz on the 100k half-sphere after a slide).
TEST(HapticLoop, ANewContactModelMovesTheProbeWithoutADamperImpulse) {
  VirtualDevice device = still_device();
  WorkspaceMapping mapping;
  const double k = 500, b = 3;
  ForceRules rules;
  rules.ramp_time = 0;
  rules.max_change = 100;
  rules.passivity_control = false;
  HapticLoop loop(device, mapping, CouplingGains{k, b}, rules, 1000.0);
  ContactModel m;
  m.p0 = Vec3(0, -1e-3, 0);
  m.f0 = Vec3(0, 0.5, 0);
  m.K = -5000 * Mat3::Identity();
  m.contacts = 3;
  for (int tick = 1; tick <= 10; ++tick) ASSERT_TRUE(loop.tick(tick * 1e-3, 1e-3));  // engaged before the contact
  loop.contact_models().back() = m;
  loop.contact_models().publish();
  for (int tick = 11; tick <= 300; ++tick) ASSERT_TRUE(loop.tick(tick * 1e-3, 1e-3));
  loop.frames().update();
  const HapticFrame before = loop.frames().front();
  // the simulation's next model pushes 0.1 N harder: the probe jumps by 0.1 / (k + 5000) = 18 um up
  m.f0.y() += 0.1;
  loop.contact_models().back() = m;
  loop.contact_models().publish();
  ASSERT_TRUE(loop.tick(0.301, 1e-3));
  loop.frames().update();
  const HapticFrame& after = loop.frames().front();
  EXPECT_GT((after.probe - before.probe).y(), 15e-6);
  // the force is the spring's, k (p - d), up to the damper on the device's own slow motion: not b 18 um / 1 ms = 55 mN
  EXPECT_LT((after.force - k * (after.probe - after.device)).norm(), 5e-3);
  EXPECT_NEAR((after.force - before.force).y(), k * (after.probe - before.probe).y(), 5e-3);
}

}  // namespace
}  // namespace pointhaptics
