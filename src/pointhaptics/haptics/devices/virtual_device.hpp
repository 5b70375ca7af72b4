#pragma once
/// @file A virtual device: a hand following a scripted trajectory through simple hand/device dynamics,
/// so that the force it is given acts back on it and closed loops can be tested without hardware.
#include <pointhaptics/haptics/device.hpp>
#include <pointhaptics/haptics/hand_dynamics.hpp>
#include <pointhaptics/haptics/trajectory.hpp>

namespace pointhaptics {

class VirtualDevice : public Device {
 public:
  VirtualDevice(Trajectory trajectory, const DeviceSpecs& specs, const HandDynamics& hand = {});
  DeviceSpecs specs() const override { return specs_; }
  DeviceState read(double t) override;  ///< advances the dynamics to t (sub-steps of at most 0.25 ms)
  void command(const Vec3& force) override;
  void stop() override { endpoint_.set_force(Vec3::Zero()); }

 private:
  Trajectory trajectory_;
  DeviceSpecs specs_;
  HandEndpoint endpoint_;
};

}  // namespace pointhaptics
