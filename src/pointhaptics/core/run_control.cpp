#include <pointhaptics/core/run_control.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

namespace pointhaptics {

namespace {

std::atomic<bool> stop_request{false};
static_assert(std::atomic<bool>::is_always_lock_free, "a signal handler may only touch lock-free atomics");
std::atomic<ProgressSink*> progress_sink{nullptr};

// the sink is told at most every 50 ms, by one thread at a time (the others skip their report, never wait)
std::mutex report_mutex;
std::chrono::steady_clock::time_point last_report;
constexpr auto report_interval = std::chrono::milliseconds(50);

}  // namespace

void request_stop() noexcept { stop_request.store(true, std::memory_order_relaxed); }
void clear_stop_request() noexcept { stop_request.store(false, std::memory_order_relaxed); }
bool stop_requested() noexcept { return stop_request.load(std::memory_order_relaxed); }

void throw_if_stop_requested(const char* where) {
  if (stop_requested()) throw Interrupted(std::string("interrupted during ") + where);
}

void set_progress_sink(ProgressSink* sink) noexcept { progress_sink.store(sink); }

void announce(const std::string& message) {
  ProgressSink* sink = progress_sink.load();
  if (!sink) return;
  const std::lock_guard lock(report_mutex);
  sink->announce(message);
}

std::string format_duration(double seconds) {
  char text[64];
  if (!(seconds < 120)) {
    if (seconds < 7200) std::snprintf(text, sizeof text, "%.0f min", seconds / 60);
    else std::snprintf(text, sizeof text, "%.1f h", seconds / 3600);
  } else {
    std::snprintf(text, sizeof text, "%.0f s", seconds);
  }
  return text;
}

Progress::Progress(const char* phase, double total) : phase_(phase), total_(total > 0 ? total : 1) {
  throw_if_stop_requested(phase_);
}

Progress::~Progress() {
  ProgressSink* sink = progress_sink.load();
  if (!sink) return;
  const std::lock_guard lock(report_mutex);
  sink->finished(phase_);
}

void Progress::advance(double amount) {
  throw_if_stop_requested(phase_);
  const double done = done_.fetch_add(amount, std::memory_order_relaxed) + amount;
  report(done);
}

void Progress::reach(double done) {
  throw_if_stop_requested(phase_);
  done_.store(done, std::memory_order_relaxed);
  report(done);
}

void Progress::report(double done) {
  ProgressSink* sink = progress_sink.load(std::memory_order_relaxed);
  if (!sink) return;
  const std::unique_lock lock(report_mutex, std::try_to_lock);
  if (!lock.owns_lock()) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_report < report_interval) return;
  last_report = now;
  sink->progress(phase_, std::min(1.0, done / total_));
}

}  // namespace pointhaptics
