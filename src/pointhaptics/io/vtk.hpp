#pragma once
/// @file ParaView output: VTK XML PolyData frames (.vtp) and their time series (.pvd).
#include <pointhaptics/core/types.hpp>

#include <array>
#include <string>
#include <vector>

namespace pointhaptics {

/// A point-data array of a frame: `components` values per point (1 scalar, 3 vector, 9 tensor).
struct VtkArray {
  std::string name;
  int components = 1;
  std::vector<double> values;  ///< components x n, point by point
  bool integer = false;        ///< written as UInt8 (flags)
};

/// Triangles of a frame, by rows of its points, counter-clockwise seen from outside.
using VtkTriangles = std::vector<std::array<index_t, 3>>;

/// Write one frame: the points (3 x n, m) as vertices, or with `triangles` as the polygons of a surface, with
/// the arrays as point data (ASCII, so that any VTK reader opens it). Throws Error naming the file if it
/// cannot be written or an array has the wrong size.
void write_vtp(const std::string& path, const Points& points, const std::vector<VtkArray>& arrays,
               const VtkTriangles& triangles = {});

/// A time series in a folder: frame files `<base>_<k>.vtp` and the collection `<base>.pvd` that ParaView
/// opens as one animated data set (rewritten after every frame, so a run that stops early leaves a valid
/// series). A frame may have a second part, a surface (`<base>_surface_<k>.vtp`, part 1 of the same
/// time step). Creates the folder.
class VtkSeries {
 public:
  explicit VtkSeries(std::string folder, std::string base = "frame");
  /// Write a frame at `time` (s); returns its path.
  std::string add(double time, const Points& points, const std::vector<VtkArray>& arrays);
  /// Write the surface of the frame last added (same time step, part 1); returns its path.
  std::string add_surface(const Points& vertices, const VtkTriangles& triangles, const std::vector<VtkArray>& arrays);
  const std::string& collection_path() const { return pvd_; }
  int frames() const { return frames_; }

 private:
  struct Entry {
    double time;
    int part;
    std::string file;
  };
  void write_collection() const;
  std::string folder_, base_, pvd_;
  std::vector<Entry> entries_;
  int frames_ = 0;
};

}  // namespace pointhaptics
