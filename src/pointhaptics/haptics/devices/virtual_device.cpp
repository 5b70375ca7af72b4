#include <pointhaptics/haptics/devices/virtual_device.hpp>

namespace pointhaptics {

VirtualDevice::VirtualDevice(Trajectory trajectory, const DeviceSpecs& specs, const HandDynamics& hand)
    : trajectory_(std::move(trajectory)), specs_(specs), endpoint_(hand, trajectory_.position(0.0)) {}

DeviceState VirtualDevice::read(double t) {
  endpoint_.advance(t, [this](double tk) { return trajectory_.position(tk); });
  DeviceState s;
  s.time = endpoint_.time();
  s.position = endpoint_.position();
  s.velocity = endpoint_.velocity();
  s.buttons = trajectory_.button(s.time) ? 1u : 0u;
  return s;
}

void VirtualDevice::command(const Vec3& force) {
  if (!force.allFinite()) throw DeviceError("virtual device: commanded a non-finite force");
  endpoint_.set_force(force);
}

}  // namespace pointhaptics
