#include <pointhaptics/core/parameters.hpp>

#include <cmath>

namespace pointhaptics {

double MaterialParams::p_wave_speed() const { return std::sqrt((lambda() + 2.0 * mu() + volume_stiffness) / density); }

bool valid_prony(const std::vector<PronyTerm>& series) {
  if (series.empty() || series.size() > max_prony_terms) return false;
  double sum = 0;
  for (const PronyTerm& t : series) {
    if (!(t.g > 0 && t.g < 1) || !(t.tau >= 1e-6 && t.tau <= 1e6)) return false;
    sum += t.g;
  }
  return sum < 1;
}

}  // namespace pointhaptics
