#pragma once
/// @file Reading point clouds from text files (.xyz, .csv): one point per line, x y z in metres.
#include <pointhaptics/core/point_cloud.hpp>

#include <string>

namespace pointhaptics {

/// Read an .xyz (whitespace-separated) or .csv (comma-separated) cloud; lines starting with '#' and a
/// non-numeric header line are skipped. Each point gets volume spacing^3. Throws Error naming the file
/// and line for a missing file, a malformed line, a non-finite coordinate or an empty cloud; other
/// formats (.ply, meshes, volume images) are refused with a clear message.
PointCloud read_point_cloud(const std::string& path, double spacing);

}  // namespace pointhaptics
