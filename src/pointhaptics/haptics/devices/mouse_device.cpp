#include <pointhaptics/haptics/devices/mouse_device.hpp>

namespace pointhaptics {

MouseDevice::MouseDevice(const DeviceSpecs& specs, const Vec3& start, const HandDynamics& hand)
    : specs_(specs), endpoint_(hand, start), aims_(Aim{start, 0}), last_target_(start) {}

DeviceState MouseDevice::read(double t) {
  aims_.update();
  const Aim& aim = aims_.front();
  endpoint_.advance(t, [&aim](double) { return aim.target; });
  DeviceState s;
  s.time = endpoint_.time();
  s.position = endpoint_.position();
  s.velocity = endpoint_.velocity();
  s.buttons = aim.buttons;
  return s;
}

void MouseDevice::command(const Vec3& force) {
  if (!force.allFinite()) throw DeviceError("mouse device: commanded a non-finite force");
  endpoint_.set_force(force);
}

void MouseDevice::set_target(const Vec3& target, unsigned buttons) {
  if (!target.allFinite()) return;
  aims_.back() = {target, buttons};
  aims_.publish();
  last_target_ = target;
}

}  // namespace pointhaptics
