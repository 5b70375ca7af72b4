#include <pointhaptics/haptics/haptic_loop.hpp>

#include <pointhaptics/haptics/coupling.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>

#include <pthread.h>
#include <sched.h>

namespace pointhaptics {

HapticLoop::HapticLoop(Device& device, const WorkspaceMapping& mapping, const CouplingGains& gains,
                       const ForceRules& rules, double rate_hz, std::size_t log_capacity)
    : device_(device),
      mapping_(mapping),
      gains_(gains),
      renderer_(device.specs(), rules),
      period_(1.0 / rate_hz),
      device_max_force_(device.specs().max_force),
      log_(log_capacity) {
  if (!(rate_hz > 0) || !(mapping.scale > 0) || !(gains.stiffness > 0))
    throw Error("haptic loop: the rate, the workspace scale and the coupling stiffness must be positive");
}

HapticLoop::~HapticLoop() { stop(); }

bool HapticLoop::tick(double t, double dt) {
  if (failed_) return false;
  try {
    const DeviceState state = device_.read(t);
    const Vec3 d = mapping_.origin + mapping_.scale * state.position;  // the device point in the scene
    const Vec3 vd = mapping_.scale * state.velocity;
    models_.update();
    const ContactModel& m = models_.front();
    // the probe is where the coupling spring balances the local contact model (haptics/coupling.hpp)
    const double k = gains_.stiffness;
    const bool touching = m.contacts > 0 && m.p0.allFinite();
    const Vec3 p = touching ? coupled_probe(m, d, k, device_max_force_) : d;
    // the probe's velocity for the coupling's damper: how far this tick's contact model moves it as the device
    // moved since the last tick. A new model from the simulation moves the probe at once (the contact solved
    // again); differentiated, that jump made a force impulse b dp/dt at every simulation step, a buzz of
    // 150-500 Hz on the 100k half-sphere after a slide (docs/haptics.md)
    Vec3 vp = vd;
    if (last_device_.allFinite() && dt > 0) {
      const Vec3 before = touching ? coupled_probe(m, last_device_, k, device_max_force_) : last_device_;
      vp = (p - before) / dt;
    }
    probe_ = p;
    last_device_ = d;
    // the coupling pulls the device toward the probe (scene forces are rendered unscaled)
    const Vec3 requested = k * (p - d) + gains_.damping * (vp - vd);
    const Vec3 f = renderer_.render(requested, state.velocity, dt);
    // the tool's torque from the contact (a capsule pressed off its centre): zero on a device that renders none
    const Vec3 torque = renderer_.render_torque(m.contacts > 0 ? m.torque : Vec3::Zero());
    device_.set_torque(torque);
    device_.command(f);
    HapticFrame& frame = frames_.back();
    frame.time = t;
    frame.probe = p;
    frame.device = d;
    frame.button = (state.buttons & 1u) != 0;
    frame.orientation = state.orientation;
    frame.force = f;
    frame.torque = torque;
    frame.tick = ticks_ + 1;
    frames_.publish();
    if (log_.capacity() > 0 && !log_.push({t, state.position, state.velocity, state.buttons, f, torque}))
      log_dropped_.fetch_add(1, std::memory_order_relaxed);
    max_force_ = std::max(max_force_, f.norm());
    ++ticks_;
    last_t_ = t;
    return true;
  } catch (const DeviceError& e) {
    failed_ = true;
    error_ = e.what();
  } catch (const Error& e) {
    failed_ = true;
    error_ = e.what();
  }
  failed_flag_.store(true, std::memory_order_release);
  renderer_.reset();
  try {
    device_.stop();  // zero force, whatever happened
  } catch (...) {}
  return false;
}

void HapticLoop::record_period(double error_us) {
  const auto bin = static_cast<std::size_t>(std::min(std::abs(error_us), 2000.0));
  ++period_histogram_[bin];
}

void HapticLoop::start() {
  if (running_.exchange(true)) return;
  thread_ = std::thread([this] { run(); });
}

void HapticLoop::stop() {
  if (!running_.exchange(false)) return;
  if (thread_.joinable()) thread_.join();
}

void HapticLoop::run() {
  // ask for real-time scheduling; without the privilege (the usual case) the loop runs as it is
  sched_param priority{};
  priority.sched_priority = 80;
  realtime_priority_ = pthread_setschedparam(pthread_self(), SCHED_FIFO, &priority) == 0;
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  const auto period = std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(period_));
  auto deadline = start;
  auto previous = start;
  int spin_us = 400;
  while (running_.load(std::memory_order_relaxed)) {
    deadline += period;
    // absolute deadlines (no drift): sleep until shortly before, then spin, because a sleeping thread
    // wakes up late by up to the scheduler's slack (hundreds of us on a loaded machine). The spin margin
    // follows the lateness seen: up at once past a late wake-up, down by 1 us per tick when wake-ups are
    // punctual, within [60, 400] us; spinning is CPU the simulation does not get on a small machine
    const auto wake = deadline - std::chrono::microseconds(spin_us);
    std::this_thread::sleep_until(wake);
    const double late_us = std::chrono::duration<double, std::micro>(clock::now() - wake).count();
    if (late_us > spin_us - 50) spin_us = std::min(400, static_cast<int>(late_us) + 100);
    else if (spin_us > 60) --spin_us;
    spin_us_sum_ += spin_us;
    while (clock::now() < deadline) {}
    const auto now = clock::now();
    const double t = std::chrono::duration<double>(now - start).count();
    const double dt = std::chrono::duration<double>(now - previous).count();
    if (ticks_ > 0) record_period(1e6 * (dt - period_));
    previous = now;
    const bool ok = tick(t, dt);
    tick_max_us_ = std::max(tick_max_us_, 1e6 * std::chrono::duration<double>(clock::now() - now).count());
    if (!ok) break;
    // after a stall, do not try to catch up with a burst of ticks
    if (clock::now() - deadline > 10 * period) deadline = clock::now();
  }
  wall_s_ = std::chrono::duration<double>(clock::now() - start).count();
  try {
    device_.stop();
  } catch (...) {}
}

HapticStats HapticLoop::stats() const {
  HapticStats s;
  s.ticks = ticks_;
  const double span = wall_s_ > 0 ? wall_s_ : last_t_;
  s.rate_hz = span > 0 ? static_cast<double>(ticks_) / span : 0.0;
  long long total = 0;
  for (long long c : period_histogram_) total += c;
  auto quantile = [&](double q) {
    long long seen = 0;
    for (std::size_t b = 0; b < period_histogram_.size(); ++b) {
      seen += period_histogram_[b];
      if (total > 0 && seen >= q * total) return static_cast<double>(b);
    }
    return 0.0;
  };
  s.period_p50_us = quantile(0.5);
  s.period_p99_us = quantile(0.99);
  for (std::size_t b = period_histogram_.size(); b-- > 0;)
    if (period_histogram_[b]) {
      s.period_max_us = static_cast<double>(b);
      break;
    }
  s.tick_max_us = tick_max_us_;
  s.spin_mean_us = s.ticks > 0 ? spin_us_sum_ / static_cast<double>(s.ticks) : 0.0;
  s.max_force_n = max_force_;
  s.min_observed_energy = renderer_.min_observed_energy();
  s.passivity_dissipated = renderer_.controller_dissipated();
  s.passivity_ticks = renderer_.controller_ticks();
  s.device_failed = failed_;
  s.realtime_priority = realtime_priority_;
  s.device_error = error_;
  return s;
}

}  // namespace pointhaptics
