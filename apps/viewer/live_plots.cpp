#include "live_plots.hpp"

#include <algorithm>

namespace pointhaptics::viewer {

RollingSeries::RollingSeries(double window_s, std::size_t capacity)
    : window_(window_s), capacity_(std::max<std::size_t>(capacity, 1)), time_(capacity_), value_(capacity_) {}

void RollingSeries::push(double t, float value) {
  time_[head_] = t;
  value_[head_] = value;
  head_ = (head_ + 1) % capacity_;
  count_ = std::min(count_ + 1, capacity_);
}

void RollingSeries::values(std::vector<float>& out) const {
  out.clear();
  if (!count_) return;
  const double latest = time_[(head_ + capacity_ - 1) % capacity_];
  for (std::size_t k = 0; k < count_; ++k) {
    const std::size_t i = (head_ + capacity_ - count_ + k) % capacity_;
    if (time_[i] >= latest - window_) out.push_back(value_[i]);
  }
}

float RollingSeries::max() const {
  std::vector<float> v;
  values(v);
  return v.empty() ? 0.0f : *std::max_element(v.begin(), v.end());
}

bool RateMeter::update(double t, long long count) {
  if (t0_ < 0 || count < count0_) {  // first call, or the counter restarted (a rebuild)
    t0_ = t;
    count0_ = count;
    return false;
  }
  if (t - t0_ < period_) return false;
  rate_ = static_cast<double>(count - count0_) / (t - t0_);
  t0_ = t;
  count0_ = count;
  return true;
}

}  // namespace pointhaptics::viewer
