// Tests for haptics/devices/virtual_device: the device follows its script through the hand dynamics, and a
// commanded force pushes it back.
#include <pointhaptics/haptics/devices/virtual_device.hpp>

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

TEST(VirtualDevice, FollowsTheScriptAndYieldsToTheForce) {
  const Trajectory tr({{0.0, Vec3::Zero(), false}, {0.5, Vec3(0, 0.02, 0), false}, {2.0, Vec3(0, 0.02, 0), false}});
  HandDynamics hand;
  VirtualDevice device(tr, known_device_specs("touch"), hand);
  DeviceState s;
  for (int k = 1; k <= 1500; ++k) {
    s = device.read(k * 1e-3);
    device.command(Vec3::Zero());
  }
  EXPECT_NEAR(s.position.y(), 0.02, 1e-4);  // settled on the target
  EXPECT_LT(s.velocity.norm(), 1e-3);
  // a constant 1.5 N pushing down: the hand gives way by F / k
  for (int k = 1501; k <= 2000; ++k) {
    device.command(Vec3(0, -1.5, 0));
    s = device.read(k * 1e-3);
  }
  EXPECT_NEAR(s.position.y(), 0.02 - 1.5 / hand.stiffness, 2e-4);
  EXPECT_THROW(device.command(Vec3(NAN, 0, 0)), DeviceError);
}

}  // namespace
}  // namespace pointhaptics
