#pragma once
/// @file A virtual device: a hand following a scripted trajectory through simple hand/device dynamics,
/// so that the force it is given acts back on it and closed loops can be tested without hardware.
#include <pointhaptics/haptics/device.hpp>
#include <pointhaptics/haptics/trajectory.hpp>

namespace pointhaptics {

/// The device endpoint is a mass m pulled toward the scripted target by the hand, a spring-damper (k, b),
/// and pushed by the commanded device force: m a = k (target - x) - b v + F.
struct HandDynamics {
  double mass = 0.1;        ///< kg, endpoint and hand
  double stiffness = 300;   ///< N/m, the hand's grip
  double damping = 6;       ///< N s/m (about 0.55 of critical for these values)
};

class VirtualDevice : public Device {
 public:
  VirtualDevice(Trajectory trajectory, const DeviceSpecs& specs, const HandDynamics& hand = {});
  DeviceSpecs specs() const override { return specs_; }
  DeviceState read(double t) override;   ///< advances the dynamics to t (sub-steps of at most 0.25 ms)
  void command(const Vec3& force) override;
  void stop() override { force_.setZero(); }

 private:
  Trajectory trajectory_;
  DeviceSpecs specs_;
  HandDynamics hand_;
  double time_ = 0;
  Vec3 x_, v_ = Vec3::Zero(), force_ = Vec3::Zero();
};

}  // namespace pointhaptics
