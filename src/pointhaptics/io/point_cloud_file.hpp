#pragma once
/// @file Reading point clouds: PLY (ASCII, binary little and big endian) and text (.xyz, .csv), with
/// optional per-point attributes, checked before anything is simulated.
#include <pointhaptics/core/point_cloud.hpp>

#include <string>
#include <string_view>

namespace pointhaptics {

/// Read a point cloud file by its extension:
/// - `.ply`: the `vertex` element's x, y, z (any PLY number type), and optionally `fixed` (non-zero: the
///   point is held) and `volume` (m^3); other properties and elements are ignored, a file with faces is a
///   surface mesh and refused here;
/// - `.xyz`, `.txt` (whitespace-separated) and `.csv` (comma-separated): one point per line, x y z and
///   optionally fixed and volume, in that order or as a header line names them (`x,y,z,volume,fixed`);
///   lines starting with '#' are comments.
/// Points without a volume get spacing^3. Throws Error naming the file (and line or vertex) for a missing
/// file, a malformed or truncated one, a count the file cannot hold, a non-finite or implausible
/// coordinate (|x| > 1e6 m: wrong endianness or units), a non-positive volume, duplicate points, and a
/// degenerate cloud (fewer than 4 points, or all on a plane or a line: no solid to simulate).
PointCloud read_point_cloud(const std::string& path, double spacing);

/// A cloud from positions given in memory (e.g. from Python), with the checks the readers make: at least 4
/// points, not flat, no duplicates, finite and plausible coordinates; volumes spacing^3. Throws Error
/// naming `name`.
PointCloud point_cloud_from_positions(const Points& X, const std::string& name, double spacing);

/// The same from the file's bytes; `format` is the extension (".ply", ".xyz", ".csv", ".txt") and `name`
/// names it in messages. For tests and fuzzing.
PointCloud parse_point_cloud(std::string_view data, std::string_view format, const std::string& name, double spacing);

}  // namespace pointhaptics
