#pragma once
/// @file From the force the simulation asks for to the force the device gets: the virtual coupling's
/// budget, and the safety rules applied every haptic tick.
#include <pointhaptics/haptics/device.hpp>

namespace pointhaptics {

/// Virtual coupling (Brown & Colgate): a spring-damper between the device and the probe in the scene.
/// A device displacement d moves the probe by `scale` d, so a scene stiffness k is felt as k scale at
/// the device; the budget keeps that below `safety` times the device's stable maximum.
struct CouplingGains {
  double stiffness = 0;  ///< N per m of scene displacement
  double damping = 0;    ///< N s per m of scene motion
};
/// scale: scene metres per device metre (> 0); safety in (0, 1].
CouplingGains coupling_budget(const DeviceSpecs& specs, double scale, double safety = 0.5);

struct ForceRules {
  double engage_below = 0.1;  ///< N: forces engage only once the requested force is below this (CHAI3D's start-up rule)
  double ramp_time = 0.5;     ///< s: after engaging, forces ramp in linearly over this time
  double max_change = 0.2;    ///< N per tick: bound on the change of the commanded force
  /// Passivity controller (Hannaford & Ryu 2002): a tick whose force would leave the observer below zero
  /// (the environment giving the hand more energy than it ever took) gets a damper against the device's
  /// velocity that dissipates the excess, its coefficient at most the force's own part along the velocity
  /// plus the device's max damping; the damped force keeps the magnitude clamp and the bound on its change
  /// per tick, so a bounded tick's excess is taken out over the next ones. Off: the observer only reports.
  bool passivity_control = true;
  /// m/s: below about this device speed the controller takes out less of the force's part along the velocity
  /// (by |v|^2 / (|v|^2 + passivity_speed^2)), and only the device's max damping stays
  double passivity_speed = 0.01;
};

/// Applies the rules to each tick's requested force: engage when small, ramp in, clamp the magnitude
/// (not each component) to the device's max force, bound the change per tick; and keeps a passivity
/// observer (Hannaford & Ryu): the energy the virtual environment has absorbed from the hand,
/// E = -sum F . v dt, which a passive environment keeps >= 0; where it would not, the passivity controller
/// (ForceRules::passivity_control) adds the damping that keeps it there. No allocation; haptic thread only.
class ForceRenderer {
 public:
  ForceRenderer(const DeviceSpecs& specs, const ForceRules& rules = {});
  /// The force to command this tick (N) for the requested one, the device velocity (m/s) and the tick (s).
  Vec3 render(const Vec3& requested, const Vec3& device_velocity, double dt);
  /// The torque to command this tick (N m) for the requested one: none before the force engages, then ramped
  /// in with it, its magnitude clamped to the device's max torque, its change per tick bounded as the force's
  /// is (the same share of its maximum). Zero for a device that renders no torque.
  Vec3 render_torque(const Vec3& requested);
  /// Zero force and torque, disengaged (e.g. after a device error or at the end).
  void reset();

  bool engaged() const { return engaged_; }
  double observed_energy() const { return energy_; }  ///< J; negative: the environment gave energy
  double min_observed_energy() const { return min_energy_; }
  double controller_dissipated() const { return dissipated_; }      ///< J the passivity controller took out
  long long controller_ticks() const { return controlled_ticks_; }  ///< ticks the passivity controller damped
  const Vec3& last_force() const { return last_; }

 private:
  /// v ramped in since engaging, then bounded().
  Vec3 limited(Vec3 v, double max, double max_change, const Vec3& last) const;
  /// v with its magnitude clamped to max (its direction kept) and its change from `last` bounded by max_change.
  static Vec3 bounded(Vec3 v, double max, double max_change, const Vec3& last);

  DeviceSpecs specs_;
  ForceRules rules_;
  bool engaged_ = false;
  double since_engaged_ = 0;
  Vec3 last_ = Vec3::Zero(), last_torque_ = Vec3::Zero();
  double energy_ = 0, min_energy_ = 0, dissipated_ = 0;
  long long controlled_ticks_ = 0;
};

}  // namespace pointhaptics
