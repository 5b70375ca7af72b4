#pragma once
/// @file A mouse (or any pointer) as a haptic device: another thread (a viewer's) says where the hand
/// wants the device point and which buttons it holds; the endpoint follows through hand dynamics, so the
/// object's force stops it at the surface instead of letting the pointer sink into the object.
#include <pointhaptics/haptics/device.hpp>
#include <pointhaptics/haptics/exchange.hpp>
#include <pointhaptics/haptics/hand_dynamics.hpp>

namespace pointhaptics {

class MouseDevice : public Device {
 public:
  /// The endpoint starts at `start` (device frame, m) with the hand aiming there.
  explicit MouseDevice(const DeviceSpecs& specs, const Vec3& start = Vec3::Zero(), const HandDynamics& hand = {});
  DeviceSpecs specs() const override { return specs_; }
  /// Haptic thread: advance the endpoint to t toward the latest target.
  DeviceState read(double t) override;
  void command(const Vec3& force) override;
  void stop() override { endpoint_.set_force(Vec3::Zero()); }

  /// Pointer thread (exactly one): where the hand aims (device frame, m) and the buttons it holds (bit k:
  /// button k). Never blocks; a non-finite target is ignored.
  void set_target(const Vec3& target, unsigned buttons);
  /// Pointer thread: the last target it set.
  const Vec3& target() const { return last_target_; }

 private:
  struct Aim {
    Vec3 target = Vec3::Zero();
    unsigned buttons = 0;
  };
  DeviceSpecs specs_;
  HandEndpoint endpoint_;
  TripleBuffer<Aim> aims_;
  Vec3 last_target_;
};

}  // namespace pointhaptics
