#pragma once
/// @file The probe on its coupling spring: where it settles against a local contact model. One function for
/// the haptic loop (every tick, on the model the simulation published) and the simulation (every step, on
/// the model at the current state).
#include <pointhaptics/haptics/contact.hpp>

namespace pointhaptics {

/// The probe position p where the coupling spring toward the device point d balances the linear contact
/// model m (linearised at m.p0):
///   k (d - p) + f0 + K (p - p0) = 0  =>  (k I - K) p = k d + f0 - K p0   (K <= 0, so always solvable).
/// The probe pushes on the object with the coupling force, and the hand cannot feel more than the device's
/// maximum, so the object is not pushed harder either: when k |d - p| exceeds max_force the device point is
/// pulled in to where the coupling force is that maximum, and the balance solved again. Returns d itself if
/// the solve is not finite.
inline Vec3 coupled_probe(const ContactModel& m, const Vec3& d, double k, double max_force) {
  const auto solver = (k * Mat3::Identity() - m.K).ldlt();
  const Vec3 rhs = m.f0 - m.K * m.p0;
  Vec3 p = solver.solve(k * d + rhs);
  const double pull = k * (d - p).norm();
  if (pull > max_force && p.allFinite()) p = solver.solve(k * (p + (d - p) * (max_force / pull)) + rhs);
  return p.allFinite() ? p : d;
}

}  // namespace pointhaptics
