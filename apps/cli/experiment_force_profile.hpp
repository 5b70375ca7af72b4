#pragma once
/// @file `pointhaptics experiment force-profile`: seed Fig. 2c, the force felt while dragging a point of
/// the beam fixed at both ends, and after letting it go.
#include <string>

namespace pointhaptics::experiments {

struct ForceProfileOptions {
  std::string out = "force-profile-out";
  bool real_time = false;  ///< run the haptic thread on the wall clock (default: deterministic, simulated time)
};

/// Writes force-profile.csv, summary.md and force-profile.png into options.out; returns the exit code.
int run_force_profile_experiment(const ForceProfileOptions& options);

}  // namespace pointhaptics::experiments
