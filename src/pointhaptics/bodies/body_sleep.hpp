#pragma once
/// @file Sleeping bodies (issue 47, item 7): a body at rest that nothing touches costs no solver time. Once every
/// point of it has been slower than sleep_speed for sleep_time with no hand touching it, it sleeps: the workspace
/// marks its points (Workspace::asleep, awake), and the explicit solver neither evaluates their stencils nor moves
/// them. It wakes when a hand touches it, a cut is made, or the force the contacts exert on it (a table's support,
/// a body resting on it, a tool) moves by more than wake_share of its weight and that force.
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/core/state.hpp>
#include <pointhaptics/core/workspace.hpp>

#include <functional>
#include <vector>

namespace pointhaptics {

/// A body sleeps once every point of it has been slower than this for sleep_time with nothing touching it, and
/// wakes when the contacts' force on it moves from what it was by more than wake_share of its weight and that force
/// (a body resting on a table: the table's support steady to 1e-4 of the weight; a hand or a tool that arrives, a
/// body that lands on it or one under it that moves change it by far more).
inline constexpr double sleep_speed = 1e-4;  // m/s
inline constexpr double sleep_time = 0.1;    // s
inline constexpr double wake_share = 0.02;

/// Body k's sleep: whether it sleeps now, and the steps it slept.
struct BodySleep {
  bool asleep = false;
  long long slept_steps = 0;
  double quiet = 0;                   ///< s its points have been slower than the sleeping speed, nothing touching it
  Vec3 dynamic_force = Vec3::Zero();  ///< the contacts' force on it when it fell asleep, N
};

/// What one step did to the bodies, for their sleep.
struct SleepInputs {
  const Points* contact_forces = nullptr;  ///< the contacts' forces on the points this step, N (null: none)
  bool cut = false;                        ///< a cut was made since the last step
  /// Whether a hand touches one of the points [first, last)
  std::function<bool(index_t first, index_t last)> touched;
  double dt = 0;  ///< the step, s
};

/// After a step: each body falls asleep or wakes (`sleep` sized to the model's bodies first; a body that falls
/// asleep has its velocities zeroed), `sleeping_steps` counts the steps slept, and the workspace's view of which
/// points sleep is rewritten when one changed.
void update_body_sleep(const Model& model, State& state, const SleepInputs& inputs, std::vector<BodySleep>& sleep,
                       long long& sleeping_steps, Workspace& ws);

}  // namespace pointhaptics
