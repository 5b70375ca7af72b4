#pragma once
/// @file A hand holding a device: the endpoint is a mass pulled toward where the hand wants it by a
/// spring-damper and pushed by the force the device renders, so that stand-in devices (scripted, mouse)
/// feel the force they are given and closed loops behave as with a person holding a real one.
#include <pointhaptics/core/types.hpp>

#include <algorithm>
#include <cmath>

namespace pointhaptics {

/// m a = k (target - x) - b v + F.
struct HandDynamics {
  double mass = 0.1;       ///< kg, endpoint and hand
  double stiffness = 300;  ///< N/m, the hand's grip
  double damping = 6;      ///< N s/m (about 0.55 of critical for these values)
};

/// The device endpoint under HandDynamics.
class HandEndpoint {
 public:
  /// Throws Error unless the mass is positive and the stiffness and damping are not negative.
  HandEndpoint(const HandDynamics& hand, const Vec3& start);
  /// Advance to time t (no-op if t is not later) in symplectic Euler sub-steps of at most 0.25 ms,
  /// the hand aiming at target(t_k) at each sub-step, with the last commanded force held.
  template <class TargetOfTime>
  void advance(double t, TargetOfTime&& target) {
    if (!(t > time_)) return;
    const int n = std::max(1, static_cast<int>(std::ceil((t - time_) / 2.5e-4)));
    const double h = (t - time_) / n;
    for (int k = 0; k < n; ++k) {
      const Vec3 a = (hand_.stiffness * (target(time_ + (k + 1) * h) - x_) - hand_.damping * v_ + force_) / hand_.mass;
      v_ += h * a;
      x_ += h * v_;
    }
    time_ = t;
  }
  void set_force(const Vec3& force) { force_ = force; }
  double time() const { return time_; }
  const Vec3& position() const { return x_; }
  const Vec3& velocity() const { return v_; }

 private:
  HandDynamics hand_;
  double time_ = 0;
  Vec3 x_, v_ = Vec3::Zero(), force_ = Vec3::Zero();
};

}  // namespace pointhaptics
