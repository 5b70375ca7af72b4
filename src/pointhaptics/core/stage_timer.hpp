#pragma once
/// @file Timing a step's stages through one helper: each stage is one call, and the wall time it took is added
/// where the diagnostics keep it, so that no timing code sits between the stages and a step reads as its table
/// of contents.
#include <chrono>
#include <utility>

namespace pointhaptics {

/// Wall-clock seconds since it was made (steady clock).
class StageClock {
 public:
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// Runs `stage` and adds the seconds it took to `total`.
template <class Stage>
void timed_stage(double& total, Stage&& stage) {
  const StageClock clock;
  std::forward<Stage>(stage)();
  total += clock.seconds();
}

}  // namespace pointhaptics
