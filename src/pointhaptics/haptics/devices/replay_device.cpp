#include <pointhaptics/haptics/devices/replay_device.hpp>

namespace pointhaptics {

ReplayDevice::ReplayDevice(std::vector<HapticLogRow> rows, const DeviceSpecs& specs)
    : rows_(std::move(rows)), specs_(specs) {
  if (rows_.empty()) throw Error("replay device: the log has no rows");
}

DeviceState ReplayDevice::read(double t) {
  // time only moves forward in a run: advance the cursor instead of searching
  if (t < rows_[cursor_].t) cursor_ = 0;
  while (cursor_ + 1 < rows_.size() && rows_[cursor_ + 1].t <= t) ++cursor_;
  const HapticLogRow& a = rows_[cursor_];
  DeviceState s;
  s.time = t;
  s.buttons = a.buttons;
  if (cursor_ + 1 < rows_.size() && t > a.t) {
    const HapticLogRow& b = rows_[cursor_ + 1];
    const double w = (t - a.t) / (b.t - a.t);
    s.position = (1 - w) * a.position + w * b.position;
    s.velocity = (1 - w) * a.velocity + w * b.velocity;
  } else {
    s.position = a.position;
    s.velocity = t > a.t ? Vec3::Zero() : a.velocity;
  }
  return s;
}

}  // namespace pointhaptics
