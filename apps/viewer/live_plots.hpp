#pragma once
/// @file Rolling time series for the viewer's live plots: the last few seconds of a quantity sampled at
/// the frame rate, and rate meters made from counters (steps, haptic ticks).
#include <cstddef>
#include <vector>

namespace pointhaptics::viewer {

/// The samples of the last `window` seconds, oldest first, in a fixed ring (no allocation after construction).
class RollingSeries {
 public:
  RollingSeries(double window_s, std::size_t capacity);
  void push(double t, float value);
  /// The samples within the window of the latest time, oldest first, copied into `out`.
  void values(std::vector<float>& out) const;
  float latest() const { return count_ ? value_[(head_ + capacity_ - 1) % capacity_] : 0.0f; }
  float max() const;  ///< of the samples in the window (0 if none)
  std::size_t size() const { return count_; }

 private:
  double window_;
  std::size_t capacity_, head_ = 0, count_ = 0;
  std::vector<double> time_;
  std::vector<float> value_;
};

/// Events per second of a counter, over at least `period` s of wall time.
class RateMeter {
 public:
  explicit RateMeter(double period_s = 0.5) : period_(period_s) {}
  /// Feed the counter's value at wall time t; returns true when a new rate is ready.
  bool update(double t, long long count);
  double rate() const { return rate_; }

 private:
  double period_, t0_ = -1, rate_ = 0;
  long long count0_ = 0;
};

}  // namespace pointhaptics::viewer
