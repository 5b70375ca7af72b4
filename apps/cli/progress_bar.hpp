#pragma once
// A one-line progress bar on stderr, shown only on a terminal and only once its work has lasted a second; and
// the library's long loops (run_control.hpp) shown through it.
#include <pointhaptics/core/run_control.hpp>

#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <functional>
#include <string>
#include <string_view>
#include <unistd.h>

namespace pointhaptics::cli {

class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : enabled_(enabled && isatty(STDERR_FILENO)) {}
  ~ProgressBar() { finish(); }

  void update(double fraction, const std::string& label = {}) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    if (elapsed < 1.0 || now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const int width = 40, filled = static_cast<int>(fraction * width);
    const double eta = fraction > 0 ? elapsed * (1 - fraction) / fraction : 0;
    std::fprintf(stderr, "\r%s[%s%s] %5.1f%%  %.0f s left ", label.empty() ? "" : (label + " ").c_str(),
                 std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), 100 * fraction, eta);
    std::fflush(stderr);
    shown_ = true;
  }
  void finish() {
    if (shown_) std::fprintf(stderr, "\r%100s\r", "");
    shown_ = false;
  }
  /// A new piece of work: the bar waits for its own second again.
  void restart() {
    finish();
    start_ = last_ = std::chrono::steady_clock::now();
  }

 private:
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now(), last_ = start_;
};

/// The library's long loops on the command line: a set-up phase shows a bar named after it, an announcement is
/// printed, and during the steps a long step's sub-steps are handed to `within_step` (the run's own bar); other
/// phases inside a step (a long factorisation) show their own bar.
class PhaseProgress : public ProgressSink {
 public:
  PhaseProgress(std::string scene, bool enabled) : scene_(std::move(scene)), bar_(enabled) {}
  void progress(const char* phase, double fraction) override {
    if (within_step && std::string_view(phase) == substep_phase) {
      within_step(fraction);
      return;
    }
    if (phase != phase_) {
      phase_ = phase;
      bar_.restart();
    }
    bar_.update(fraction, phase_);
  }
  void finished(const char* phase) override {
    if (!within_step || std::string_view(phase) != substep_phase) bar_.finish();
  }
  void announce(const std::string& message) override {
    bar_.finish();
    fmt::print(stderr, "pointhaptics: {}: {}; Ctrl-C stops it\n", scene_, message);
  }
  void finish() { bar_.finish(); }
  /// Set while the steps run: the fraction of the current step done.
  std::function<void(double)> within_step;

 private:
  std::string scene_;
  std::string phase_;
  ProgressBar bar_;
};

}  // namespace pointhaptics::cli
