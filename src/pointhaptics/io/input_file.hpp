#pragma once
/// @file Input files checked before a reader opens them.
#include <cstdint>
#include <string>
#include <string_view>

namespace pointhaptics {

/// Check that `path` is a regular file that can be read and return its size in bytes. A folder, a FIFO or
/// a device (/dev/zero) would block a reader or feed it without end (issue 21), so each is a named error;
/// `what` says which input it is (e.g. "point cloud").
std::uintmax_t check_input_file(const std::string& path, std::string_view what);

/// The extension of `path` in lower case, with its dot (".ply" for "Scan.PLY"; "" without one): what the
/// readers and writers choose a format by.
std::string file_extension(const std::string& path);

}  // namespace pointhaptics
