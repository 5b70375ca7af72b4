#include <pointhaptics/core/parameters.hpp>

#include <cmath>

namespace pointhaptics {

double MaterialParams::p_wave_speed() const {
  return std::sqrt((lambda() + 2.0 * mu() + volume_stiffness) / density);
}

std::string_view to_string(KernelType type) {
  switch (type) {
    case KernelType::POLY6: return "poly6";
    case KernelType::SPIKY: return "spiky";
    case KernelType::VISCOSITY: return "viscosity";
    case KernelType::QUADRATIC: return "quadratic";
  }
  return "?";
}

std::string_view to_string(VolumeMode mode) { return mode == VolumeMode::CELL ? "cell" : "kernel"; }

std::string_view to_string(LodScheme scheme) { return scheme == LodScheme::RANDOM ? "random" : "dither"; }

}  // namespace pointhaptics
