#pragma once
/// @file Replay of a recorded session (a haptic log): the device follows the recorded positions, open
/// loop; the forces it is given are ignored (the log has the forces that were felt then).
#include <pointhaptics/haptics/device.hpp>
#include <pointhaptics/haptics/haptic_loop.hpp>

#include <vector>

namespace pointhaptics {

class ReplayDevice : public Device {
 public:
  ReplayDevice(std::vector<HapticLogRow> rows, const DeviceSpecs& specs);
  DeviceSpecs specs() const override { return specs_; }
  DeviceState read(double t) override;  ///< linear between rows, held after the last one
  void command(const Vec3&) override {}
  double duration() const { return rows_.back().t; }

 private:
  std::vector<HapticLogRow> rows_;
  DeviceSpecs specs_;
  std::size_t cursor_ = 0;
};

}  // namespace pointhaptics
