#pragma once
/// @file The haptic log: one row per tick (time, device position and velocity, buttons, force), as CSV.
/// The replay device reads the same format back.
#include <pointhaptics/core/types.hpp>
#include <pointhaptics/io/output_file.hpp>

#include <string>
#include <vector>

namespace pointhaptics {

/// One row of the haptic log (the format replay reads): time, device position and velocity, buttons, force.
struct HapticLogRow {
  double t = 0;
  Vec3 position = Vec3::Zero(), velocity = Vec3::Zero();
  unsigned buttons = 0;
  Vec3 force = Vec3::Zero();
  Vec3 torque = Vec3::Zero();  ///< commanded, N m (zero on a device that renders none)
};

/// Header: t,x,y,z,vx,vy,vz,buttons,fx,fy,fz,tx,ty,tz (s, m, m/s, bit mask, N, N m; device frame). A log of
/// the first 11 columns (before the torque's) reads with zero torque.
void write_haptic_log(const std::string& path, const std::vector<HapticLogRow>& rows);
/// The same file streamed row by row (a run of any length): the header, then one call per row.
void print_haptic_log_header(TextOutput& out);
void print_haptic_log_row(TextOutput& out, const HapticLogRow& row);
/// Throws Error naming the file and line for a malformed, non-finite or out-of-order row.
std::vector<HapticLogRow> read_haptic_log(const std::string& path);

}  // namespace pointhaptics
