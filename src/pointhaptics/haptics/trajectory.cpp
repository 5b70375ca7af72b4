#include <pointhaptics/haptics/trajectory.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/input_file.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace pointhaptics {

Trajectory::Trajectory(std::vector<Keyframe> keyframes) : keyframes_(std::move(keyframes)) {
  for (std::size_t k = 0; k < keyframes_.size(); ++k) {
    const Keyframe& f = keyframes_[k];
    if (!std::isfinite(f.t) || !f.position.allFinite())
      throw Error(fmt::format("trajectory keyframe {}: non-finite time or position", k));
    if (k > 0 && !(f.t > keyframes_[k - 1].t))
      throw Error(fmt::format("trajectory keyframe {}: time {} s does not follow {} s", k, f.t, keyframes_[k - 1].t));
  }
}

Trajectory Trajectory::from_csv(const std::string& path) {
  check_input_file(path, "trajectory file");
  std::ifstream in(path);
  if (!in) throw Error(fmt::format("{}: cannot open the trajectory file", path));
  std::vector<Keyframe> frames;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream tokens(line);
    std::vector<std::string> words;
    for (std::string w; tokens >> w;) words.push_back(w);
    if (words.empty()) continue;
    double v[5] = {0, 0, 0, 0, 0};
    bool numeric = words.size() == 4 || words.size() == 5;
    for (std::size_t k = 0; numeric && k < words.size(); ++k) {
      char* end = nullptr;
      v[k] = std::strtod(words[k].c_str(), &end);
      numeric = end != words[k].c_str() && *end == '\0' && std::isfinite(v[k]);
    }
    if (!numeric) {
      if (frames.empty() && line_no == 1) continue;  // a header
      throw Error(fmt::format("{}:{}: expected \"t, x, y, z[, button]\" with finite numbers", path, line_no));
    }
    frames.push_back({v[0], Vec3(v[1], v[2], v[3]), words.size() == 5 && v[4] != 0});
  }
  if (frames.empty()) throw Error(fmt::format("{}: no keyframes", path));
  try {
    return Trajectory(std::move(frames));
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {}", path, e.what()));
  }
}

std::size_t Trajectory::segment(double t) const {
  const auto it = std::upper_bound(keyframes_.begin(), keyframes_.end(), t,
                                   [](double time, const Keyframe& f) { return time < f.t; });
  return it == keyframes_.begin() ? 0 : static_cast<std::size_t>(it - keyframes_.begin()) - 1;
}

Vec3 Trajectory::position(double t) const {
  if (keyframes_.empty()) return Vec3::Zero();
  const std::size_t k = segment(t);
  if (t <= keyframes_.front().t || k + 1 >= keyframes_.size())
    return keyframes_[t <= keyframes_.front().t ? 0 : k].position;
  const Keyframe &a = keyframes_[k], &b = keyframes_[k + 1];
  const double s = (t - a.t) / (b.t - a.t);
  return (1 - s) * a.position + s * b.position;
}

bool Trajectory::button(double t) const {
  if (keyframes_.empty() || t < keyframes_.front().t) return false;
  return keyframes_[segment(t)].button;
}

}  // namespace pointhaptics
