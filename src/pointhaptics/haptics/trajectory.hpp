#pragma once
/// @file A scripted hand trajectory: keyframes (t, position, button), linear in between.
#include <pointhaptics/core/types.hpp>

#include <string>
#include <vector>

namespace pointhaptics {

struct Keyframe {
  double t = 0;                  ///< s
  Vec3 position = Vec3::Zero();  ///< m, in the device frame
  bool button = false;           ///< held from this keyframe to the next
};

class Trajectory {
 public:
  Trajectory() = default;
  /// Keyframes in increasing time (throws Error naming the offending keyframe otherwise).
  explicit Trajectory(std::vector<Keyframe> keyframes);
  /// Reads "t, x, y, z[, button]" lines (commas or spaces; '#' comments; an optional header line);
  /// throws Error naming the file and line for anything malformed.
  static Trajectory from_csv(const std::string& path);
  Vec3 position(double t) const;  ///< held at the ends
  bool button(double t) const;
  double duration() const { return keyframes_.empty() ? 0.0 : keyframes_.back().t; }
  const std::vector<Keyframe>& keyframes() const { return keyframes_; }

 private:
  std::size_t segment(double t) const;
  std::vector<Keyframe> keyframes_;
};

}  // namespace pointhaptics
