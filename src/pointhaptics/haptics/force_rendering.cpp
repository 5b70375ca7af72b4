#include <pointhaptics/haptics/force_rendering.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace pointhaptics {

CouplingGains coupling_budget(const DeviceSpecs& specs, double scale, double safety) {
  if (!(scale > 0) || !std::isfinite(scale))
    throw Error(fmt::format("coupling: workspace scale {} must be positive", scale));
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

Vec3 ForceRenderer::limited(Vec3 v, double max, double max_change, const Vec3& last) const {
  if (rules_.ramp_time > 0) v *= std::min(1.0, since_engaged_ / rules_.ramp_time);
  return bounded(v, max, max_change, last);
}

Vec3 ForceRenderer::bounded(Vec3 v, double max, double max_change, const Vec3& last) {
  const double magnitude = v.norm();
  if (magnitude > max) v *= max / magnitude;  // keep the direction
  const Vec3 change = v - last;
  if (change.norm() > max_change) v = last + change * (max_change / change.norm());
  return v;
}

Vec3 ForceRenderer::render_torque(const Vec3& requested) {
  if (!(specs_.max_torque > 0) || !engaged_ || !requested.allFinite()) return last_torque_ = Vec3::Zero();
  // its change per tick bounded by the same share of its maximum as the force's
  return last_torque_ = limited(requested, specs_.max_torque, rules_.max_change * specs_.max_torque / specs_.max_force,
                                last_torque_);
}

Vec3 ForceRenderer::render(const Vec3& requested, const Vec3& device_velocity, double dt) {
  Vec3 f = requested.allFinite() ? requested : Vec3::Zero();  // a NaN never reaches the device
  if (!engaged_ && f.norm() < rules_.engage_below) {
    engaged_ = true;
    since_engaged_ = 0;
  }
  if (engaged_) since_engaged_ += dt;
  f = limited(engaged_ ? f : Vec3::Zero(), specs_.max_force, rules_.max_change, last_);
  if (!device_velocity.allFinite()) return last_ = f;
  // passivity observer: the hand does work -F.v dt on the environment
  const double observed = energy_ - f.dot(device_velocity) * dt;
  const double speed2 = device_velocity.squaredNorm(), damper_work = speed2 * dt;  // per unit damping coefficient
  if (rules_.passivity_control && engaged_ && observed < 0 && damper_work > 0) {
    // passivity controller: the damping alpha that dissipates the excess this tick, alpha |v|^2 dt = -E, at
    // most the device's max damping and the part of the force along the velocity (the part that gives the hand
    // energy), the latter faded out below passivity_speed: where the hand is nearly still the velocity's
    // direction wanders, and taking the force's part along it out made the force jump from tick to tick
    const double slow2 = rules_.passivity_speed * rules_.passivity_speed;
    const double giving = std::max(0.0, f.dot(device_velocity)) / (speed2 + slow2);
    const double alpha = std::min(giving + specs_.max_damping, -observed / damper_work);
    // the rules hold for the damped force too (magnitude, change per tick): what a bounded change lets
    // through this tick the next ticks take out
    const Vec3 damped = bounded(f - alpha * device_velocity, specs_.max_force, rules_.max_change, last_);
    dissipated_ += (f - damped).dot(device_velocity) * dt;
    ++controlled_ticks_;
    f = damped;
  }
  energy_ -= f.dot(device_velocity) * dt;
  min_energy_ = std::min(min_energy_, energy_);
  return last_ = f;
}

}  // namespace pointhaptics
