#include <pointhaptics/bodies/body_sleep.hpp>

#include <algorithm>

namespace pointhaptics {

namespace {

// the workspace's view: which points sleep, and the ranges that do not (none sleeping: both empty)
void mark_sleeping_points(const Model& model, const std::vector<BodySleep>& sleep, Workspace& ws) {
  ws.asleep.clear();
  ws.awake.clear();
  if (std::none_of(sleep.begin(), sleep.end(), [](const BodySleep& b) { return b.asleep; })) return;
  ws.asleep.assign(static_cast<std::size_t>(model.n_points), 0);
  for (index_t k = 0; k < model.n_bodies(); ++k) {
    const index_t first = model.body_start[static_cast<std::size_t>(k)],
                  last = model.body_start[static_cast<std::size_t>(k) + 1];
    if (sleep[static_cast<std::size_t>(k)].asleep)
      std::fill(ws.asleep.begin() + first, ws.asleep.begin() + last, char{1});
    else if (!ws.awake.empty() && ws.awake.back()[1] == first) ws.awake.back()[1] = last;
    else ws.awake.push_back({first, last});
  }
}

}  // namespace

void update_body_sleep(const Model& model, State& state, const SleepInputs& inputs, std::vector<BodySleep>& sleep,
                       long long& sleeping_steps, Workspace& ws) {
  const index_t n_bodies = model.n_bodies();
  if (sleep.size() != static_cast<std::size_t>(n_bodies)) sleep.assign(static_cast<std::size_t>(n_bodies), {});
  bool changed = false;
  for (index_t k = 0; k < n_bodies; ++k) {
    BodySleep& body = sleep[static_cast<std::size_t>(k)];
    const index_t first = model.body_start[static_cast<std::size_t>(k)],
                  last = model.body_start[static_cast<std::size_t>(k) + 1];
    // a cut wakes every body (it changes what holds them); a hand wakes the bodies whose points it touches
    const bool touched = inputs.touched && inputs.touched(first, last);
    Vec3 force = Vec3::Zero(), weight = Vec3::Zero();
    for (index_t i = first; i < last; ++i) {
      if (inputs.contact_forces) force += inputs.contact_forces->col(i);
      weight += model.f_ext.col(i);
    }
    if (body.asleep) {
      ++body.slept_steps;
      ++sleeping_steps;
      if (inputs.cut || touched ||
          (force - body.dynamic_force).norm() > wake_share * (weight.norm() + body.dynamic_force.norm()) + 1e-12) {
        body.asleep = false;
        body.quiet = 0;
        changed = true;
      }
      continue;
    }
    double fastest = 0;
    for (index_t i = first; i < last; ++i) fastest = std::max(fastest, state.velocity.col(i).squaredNorm());
    body.quiet = fastest < sleep_speed * sleep_speed && !touched && !inputs.cut ? body.quiet + inputs.dt : 0.0;
    if (body.quiet >= sleep_time) {
      body.asleep = true;
      body.dynamic_force = force;
      state.velocity.middleCols(first, last - first).setZero();
      changed = true;
    }
  }
  if (changed) mark_sleeping_points(model, sleep, ws);
}

}  // namespace pointhaptics
