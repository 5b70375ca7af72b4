#include <pointhaptics/haptics/local_model_stray.hpp>

namespace pointhaptics {

void LocalModelStray::add(const ContactModel& next, const Mat3& next_held) {
  const ContactModel& previous = previous_;
  if (previous.contacts > 0 && next.contacts > 0 && !previous.grabbing && !next.grabbing) {
    const Vec3 step = next.p0 - previous.p0;
    ++updates_;
    force_sum_ += next.f0.norm();
    rendered_.add((previous.f0 + previous.K * step - next.f0).norm());
    hold_.add((previous.f0 - next.f0).norm());
    held_object_.add((previous.f0 + previous_held_ * step - next.f0).norm());
  }
  previous_ = next;
  previous_held_ = next_held;
}

LocalModelSummary LocalModelStray::summary() const {
  LocalModelSummary s;
  s.updates = updates_;
  if (updates_ == 0) return s;
  const double n = static_cast<double>(updates_);
  s.force_mean_n = force_sum_ / n;
  s.rendered_mean_n = rendered_.sum / n;
  s.rendered_max_n = rendered_.max;
  s.hold_mean_n = hold_.sum / n;
  s.hold_max_n = hold_.max;
  s.held_object_mean_n = held_object_.sum / n;
  s.held_object_max_n = held_object_.max;
  return s;
}

}  // namespace pointhaptics
