#pragma once
/// @file The haptic loop: every tick (1 kHz) it reads the device, solves the probe against the latest
/// local contact model the simulation published, renders the coupling force to the device, and
/// publishes the probe for the simulation. It never waits on the simulation and never allocates.
#include <pointhaptics/io/haptic_log.hpp>
#include <pointhaptics/haptics/contact.hpp>
#include <pointhaptics/haptics/exchange.hpp>
#include <pointhaptics/haptics/force_rendering.hpp>

#include <array>
#include <atomic>
#include <string>
#include <thread>
#include <vector>

namespace pointhaptics {

/// Device frame to scene: scene = origin + scale * device.
struct WorkspaceMapping {
  Vec3 origin = Vec3::Zero();  ///< m
  double scale = 1.0;          ///< scene metres per device metre
};

/// What the haptic side publishes for the simulation every tick.
struct HapticFrame {
  double time = 0;
  Vec3 probe = Vec3::Constant(NAN);   ///< scene position of the probe (NaN until the first tick)
  Vec3 device = Vec3::Constant(NAN);  ///< scene position of the device point the coupling pulls toward
  bool button = false;
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< the device's
  Vec3 force = Vec3::Zero();                                        ///< force commanded to the device, N
  Vec3 torque = Vec3::Zero();                                       ///< torque commanded to the device, N m
  long long tick = 0;  ///< ticks so far, this one included (a reader's rate meter)
};

struct HapticStats {
  long long ticks = 0;
  double rate_hz = 0;  ///< ticks per second of wall time (threaded) or of simulated time
  double period_p50_us = 0, period_p99_us = 0, period_max_us = 0;  ///< |period - nominal| quantiles, us
  double tick_max_us = 0;                                          ///< the longest tick's own work, us
  double spin_mean_us = 0;          ///< mean busy-wait before a tick (threaded), us: CPU the loop burns
  double max_force_n = 0;           ///< largest commanded force magnitude, N
  double min_observed_energy = 0;   ///< passivity observer's minimum, J (negative: active at some point)
  double passivity_dissipated = 0;  ///< J the passivity controller took out (ForceRules::passivity_control)
  long long passivity_ticks = 0;    ///< ticks it damped
  bool device_failed = false;
  std::string device_error;
  bool realtime_priority = false;  ///< the thread got SCHED_FIFO (needs the privilege; else a normal thread)
};

class HapticLoop {
 public:
  /// log_capacity: rows of the force log the loop can hold until the consumer takes them with
  /// take_log() (0: no log); a tick that finds it full is not logged, and counted.
  HapticLoop(Device& device, const WorkspaceMapping& mapping, const CouplingGains& gains, const ForceRules& rules = {},
             double rate_hz = 1000.0, std::size_t log_capacity = 0);
  ~HapticLoop();

  /// One tick at time t (s) after the previous one dt ago; for deterministic, single-threaded runs.
  /// Returns false once the device has failed (then it commands nothing more).
  bool tick(double t, double dt);
  /// Tick on a thread at the rate, on absolute deadlines, until stop().
  void start();
  void stop();

  TripleBuffer<ContactModel>& contact_models() { return models_; }  ///< the simulation publishes here
  TripleBuffer<HapticFrame>& frames() { return frames_; }           ///< and reads the probe here
  HapticStats stats() const;                                        ///< after stop() (or between ticks)
  /// Consumer (one thread, e.g. the simulation's): hand every logged row not yet taken to `sink`, oldest
  /// first; returns how many.
  template <class Sink>
  std::size_t take_log(Sink&& sink) {
    std::size_t n = 0;
    for (HapticLogRow row; log_.pop(row); ++n) sink(row);
    return n;
  }
  /// Rows the loop could not log because the consumer had not taken the earlier ones.
  long long log_dropped() const { return log_dropped_.load(std::memory_order_relaxed); }
  const Vec3& probe() const { return probe_; }
  /// Safe from any thread: the device has failed and the loop stopped commanding it.
  bool device_failed() const { return failed_flag_.load(std::memory_order_acquire); }

 private:
  void run();
  void record_period(double error_us);

  Device& device_;
  WorkspaceMapping mapping_;
  CouplingGains gains_;
  ForceRenderer renderer_;
  double period_;
  double device_max_force_;  ///< read once: specs() builds a string, which the haptic thread must not
  TripleBuffer<ContactModel> models_;
  TripleBuffer<HapticFrame> frames_;
  SpscRing<HapticLogRow> log_;
  std::atomic<long long> log_dropped_{0};
  Vec3 probe_ = Vec3::Constant(NAN);
  Vec3 last_device_ = Vec3::Constant(NAN);  ///< the device point at the last tick, scene m
  bool failed_ = false;
  std::string error_;
  long long ticks_ = 0;
  double last_t_ = 0, tick_max_us_ = 0, max_force_ = 0, wall_s_ = 0, spin_us_sum_ = 0;
  std::array<long long, 2001> period_histogram_{};  ///< |period error| in 1 us bins, the last one open-ended
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> failed_flag_{false};
  bool realtime_priority_ = false;
};

}  // namespace pointhaptics
