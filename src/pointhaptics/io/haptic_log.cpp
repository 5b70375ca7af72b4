#include <pointhaptics/io/haptic_log.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/input_file.hpp>
#include <pointhaptics/io/output_file.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace pointhaptics {

void print_haptic_log_header(TextOutput& out) { out.print("t,x,y,z,vx,vy,vz,buttons,fx,fy,fz,tx,ty,tz\n"); }

void print_haptic_log_row(TextOutput& out, const HapticLogRow& r) {
  out.print("{:.6f},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", r.t,
            r.position.x(), r.position.y(), r.position.z(), r.velocity.x(), r.velocity.y(), r.velocity.z(), r.buttons,
            r.force.x(), r.force.y(), r.force.z(), r.torque.x(), r.torque.y(), r.torque.z());
}

void write_haptic_log(const std::string& path, const std::vector<HapticLogRow>& rows) {
  write_text_file(path, "haptic log", [&](TextOutput& out) {
    print_haptic_log_header(out);
    for (const HapticLogRow& r : rows) print_haptic_log_row(out, r);
  });
}

std::vector<HapticLogRow> read_haptic_log(const std::string& path) {
  check_input_file(path, "haptic log");
  std::ifstream in(path);
  if (!in) throw Error(fmt::format("{}: cannot open the haptic log", path));
  std::vector<HapticLogRow> rows;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line_no == 1 && line.rfind("t,", 0) == 0) continue;  // header
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream fields(line);
    // the torque's three columns came with issue 16: a log without them (11 numbers) reads with none
    double v[14] = {};
    int n = 0;
    for (std::string field; n < 15 && std::getline(fields, field, ',');) {
      char* end = nullptr;
      const double x = std::strtod(field.c_str(), &end);
      if (end == field.c_str() || (*end != '\0' && *end != '\r') || !std::isfinite(x) || n == 14) {
        n = -1;
        break;
      }
      v[n++] = x;
    }
    if (n != 11 && n != 14)
      throw Error(
          fmt::format("{}:{}: expected 14 finite numbers (t,x,y,z,vx,vy,vz,buttons,fx,fy,fz,tx,ty,tz), or the first 11",
                      path, line_no));
    // a bit mask per button: -1 and 1e30 were taken as pressed (issue 52), and their conversion was undefined
    if (!(v[7] >= 0 && v[7] <= 65535 && v[7] == std::floor(v[7])))
      throw Error(
          fmt::format("{}:{}: buttons {} is not a button mask (an integer in [0, 65535])", path, line_no, v[7]));
    HapticLogRow r{v[0],
                   Vec3(v[1], v[2], v[3]),
                   Vec3(v[4], v[5], v[6]),
                   static_cast<unsigned>(v[7]),
                   Vec3(v[8], v[9], v[10]),
                   Vec3(v[11], v[12], v[13])};
    if (!rows.empty() && !(r.t > rows.back().t))
      throw Error(fmt::format("{}:{}: time does not increase", path, line_no));
    rows.push_back(r);
  }
  if (rows.empty()) throw Error(fmt::format("{}: the haptic log has no rows", path));
  return rows;
}

}  // namespace pointhaptics
