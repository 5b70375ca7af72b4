#include <pointhaptics/haptics/force_rendering.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace pointhaptics {

CouplingGains coupling_budget(const DeviceSpecs& specs, double scale, double safety) {
  if (!(scale > 0) || !std::isfinite(scale)) throw Error(fmt::format("coupling: workspace scale {} must be positive", scale));
  if (!(safety > 0 && safety <= 1)) throw Error(fmt::format("coupling: safety {} must lie in (0, 1]", safety));
  // felt at the device: k_device = k_scene * scale, b_device = b_scene * scale
  return {safety * specs.max_stiffness / scale, safety * specs.max_damping / scale};
}

ForceRenderer::ForceRenderer(const DeviceSpecs& specs, const ForceRules& rules) : specs_(specs), rules_(rules) {}

void ForceRenderer::reset() {
  engaged_ = false;
  since_engaged_ = 0;
  last_.setZero();
  last_torque_.setZero();
}

Vec3 ForceRenderer::render_torque(const Vec3& requested) {
  if (!(specs_.max_torque > 0) || !engaged_ || !requested.allFinite()) return last_torque_ = Vec3::Zero();
  Vec3 t = requested;
  if (rules_.ramp_time > 0) t *= std::min(1.0, since_engaged_ / rules_.ramp_time);
  const double magnitude = t.norm();
  if (magnitude > specs_.max_torque) t *= specs_.max_torque / magnitude;
  const double max_change = rules_.max_change * specs_.max_torque / specs_.max_force;
  const Vec3 change = t - last_torque_;
  if (change.norm() > max_change) t = last_torque_ + change * (max_change / change.norm());
  return last_torque_ = t;
}

Vec3 ForceRenderer::render(const Vec3& requested, const Vec3& device_velocity, double dt) {
  Vec3 f = requested.allFinite() ? requested : Vec3::Zero();  // a NaN never reaches the device
  if (!engaged_ && f.norm() < rules_.engage_below) {
    engaged_ = true;
    since_engaged_ = 0;
  }
  if (!engaged_) {
    f.setZero();
  } else {
    since_engaged_ += dt;
    if (rules_.ramp_time > 0) f *= std::min(1.0, since_engaged_ / rules_.ramp_time);
  }
  const double magnitude = f.norm();
  if (magnitude > specs_.max_force) f *= specs_.max_force / magnitude;  // keep the direction
  const Vec3 change = f - last_;
  if (change.norm() > rules_.max_change) f = last_ + change * (rules_.max_change / change.norm());
  last_ = f;
  // passivity observer: the hand does work -F.v dt on the environment
  if (device_velocity.allFinite()) energy_ -= f.dot(device_velocity) * dt;
  min_energy_ = std::min(min_energy_, energy_);
  return f;
}

}  // namespace pointhaptics
