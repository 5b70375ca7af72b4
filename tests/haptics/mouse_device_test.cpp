// Tests for haptics/devices/mouse_device: the endpoint follows the target another thread sets, through the
// hand dynamics; a commanded force holds it off the target; buttons pass through; bad input is refused.
#include <pointhaptics/haptics/devices/mouse_device.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

namespace pointhaptics {
namespace {

TEST(MouseDevice, TheEndpointSettlesAtTheTargetWithTheButtons) {
  MouseDevice device(known_device_specs("touch"));
  EXPECT_EQ(device.read(0.0).position, Vec3::Zero());
  device.set_target(Vec3(0.01, -0.02, 0.005), 1u);
  DeviceState s;
  for (int k = 1; k <= 2000; ++k) s = device.read(k * 1e-3);
  EXPECT_LE((s.position - Vec3(0.01, -0.02, 0.005)).norm(), 1e-6);
  EXPECT_LE(s.velocity.norm(), 1e-4);
  EXPECT_EQ(s.buttons, 1u);
  EXPECT_EQ(device.target(), Vec3(0.01, -0.02, 0.005));
}

TEST(MouseDevice, ACommandedForceHoldsTheEndpointOffTheTarget) {
  HandDynamics hand;
  MouseDevice device(known_device_specs("touch"), Vec3::Zero(), hand);
  device.set_target(Vec3(0, -0.01, 0), 0u);
  const Vec3 push(0, 1.0, 0);  // the object pushes up with 1 N
  DeviceState s;
  for (int k = 1; k <= 3000; ++k) {
    s = device.read(k * 1e-3);
    device.command(push);
  }
  // equilibrium of the hand's spring and the force: x = target + F / k
  EXPECT_NEAR(s.position.y(), -0.01 + 1.0 / hand.stiffness, 1e-6);
  device.stop();  // zero force: back to the target
  for (int k = 3001; k <= 6000; ++k) s = device.read(k * 1e-3);
  EXPECT_NEAR(s.position.y(), -0.01, 1e-6);
}

TEST(MouseDevice, BadInputIsRefusedOrIgnored) {
  MouseDevice device(known_device_specs("touch"));
  EXPECT_THROW(device.command(Vec3(NAN, 0, 0)), DeviceError);
  device.set_target(Vec3(0.01, 0, 0), 0u);
  device.set_target(Vec3(NAN, 0, 0), 1u);  // ignored
  EXPECT_EQ(device.target(), Vec3(0.01, 0, 0));
  DeviceState s;
  for (int k = 1; k <= 2000; ++k) s = device.read(k * 1e-3);
  EXPECT_TRUE(s.position.allFinite());
  EXPECT_EQ(s.buttons, 0u);
  HandDynamics weightless;
  weightless.mass = 0;
  EXPECT_THROW(MouseDevice(known_device_specs("touch"), Vec3::Zero(), weightless), Error);
}

TEST(MouseDevice, APointerThreadSetsTargetsWhileTheHapticThreadReads) {
  MouseDevice device(known_device_specs("touch"));
  std::atomic<bool> done{false};
  std::thread pointer([&] {
    for (int k = 0; k < 20000; ++k) device.set_target(Vec3(1e-6 * (k % 100), 0, 0), k % 2);
    device.set_target(Vec3(0.02, 0, 0), 0u);
    done = true;
  });
  DeviceState s;
  double t = 0;
  while (!done.load()) s = device.read(t += 1e-4);
  pointer.join();
  for (int k = 0; k < 30000; ++k) s = device.read(t += 1e-4);
  EXPECT_NEAR(s.position.x(), 0.02, 1e-6);  // the last target wins
  EXPECT_TRUE(s.position.allFinite());
}

}  // namespace
}  // namespace pointhaptics
