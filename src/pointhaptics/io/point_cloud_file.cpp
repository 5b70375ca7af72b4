#include <pointhaptics/io/point_cloud_file.hpp>

#include <pointhaptics/core/error.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

namespace pointhaptics {

PointCloud read_point_cloud(const std::string& path, double spacing) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  std::ifstream in(path);
  if (!in) throw Error(fmt::format("{}: cannot open the point cloud file", path));
  if (ext != ".xyz" && ext != ".csv" && ext != ".txt")
    throw Error(fmt::format("{}: format \"{}\" is not readable yet (this version reads .xyz and .csv point clouds)", path, ext));
  std::vector<Vec3> points;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::replace(line.begin(), line.end(), ',', ' ');
    const char* p = line.data();
    const char* end = p + line.size();
    while (p < end && std::isspace(static_cast<unsigned char>(*p))) ++p;
    if (p == end || *p == '#') continue;
    Vec3 x;
    int count = 0;
    for (; count < 3; ++count) {
      while (p < end && std::isspace(static_cast<unsigned char>(*p))) ++p;
      auto [next, ec] = std::from_chars(p, end, x[count]);
      if (ec != std::errc()) break;
      p = next;
    }
    if (count < 3) {
      if (points.empty() && line_no == 1) continue;  // a header line
      throw Error(fmt::format("{}:{}: expected three numbers x y z", path, line_no));
    }
    if (!x.allFinite()) throw Error(fmt::format("{}:{}: coordinate is not finite", path, line_no));
    points.push_back(x);
  }
  if (points.empty()) throw Error(fmt::format("{}: the file holds no points", path));
  PointCloud cloud;
  cloud.spacing = spacing;
  cloud.X.resize(3, static_cast<Eigen::Index>(points.size()));
  for (size_t i = 0; i < points.size(); ++i) cloud.X.col(static_cast<Eigen::Index>(i)) = points[i];
  cloud.volume = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(points.size()), spacing * spacing * spacing);
  cloud.surface.assign(points.size(), 0);
  return cloud;
}

}  // namespace pointhaptics
