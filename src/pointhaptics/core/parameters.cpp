#include <pointhaptics/core/parameters.hpp>

#include <cmath>

namespace pointhaptics {

double MaterialParams::p_wave_speed() const {
  return std::sqrt((lambda() + 2.0 * mu() + volume_stiffness) / density);
}

}  // namespace pointhaptics
