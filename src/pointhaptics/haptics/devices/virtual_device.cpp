#include <pointhaptics/haptics/devices/virtual_device.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace pointhaptics {

VirtualDevice::VirtualDevice(Trajectory trajectory, const DeviceSpecs& specs, const HandDynamics& hand)
    : trajectory_(std::move(trajectory)), specs_(specs), hand_(hand), x_(trajectory_.position(0.0)) {
  if (!(hand.mass > 0) || !(hand.stiffness >= 0) || !(hand.damping >= 0))
    throw Error("virtual device: the hand needs a positive mass and non-negative stiffness and damping");
}

DeviceState VirtualDevice::read(double t) {
  if (t > time_) {
    const int n = std::max(1, static_cast<int>(std::ceil((t - time_) / 2.5e-4)));
    const double h = (t - time_) / n;
    for (int k = 0; k < n; ++k) {
      const double tk = time_ + (k + 1) * h;
      const Vec3 a = (hand_.stiffness * (trajectory_.position(tk) - x_) - hand_.damping * v_ + force_) / hand_.mass;
      v_ += h * a;  // symplectic Euler
      x_ += h * v_;
    }
    time_ = t;
  }
  DeviceState s;
  s.time = time_;
  s.position = x_;
  s.velocity = v_;
  s.buttons = trajectory_.button(time_) ? 1u : 0u;
  return s;
}

void VirtualDevice::command(const Vec3& force) {
  if (!force.allFinite()) throw DeviceError("virtual device: commanded a non-finite force");
  force_ = force;
}

}  // namespace pointhaptics
