#include <pointhaptics/core/memory_limit.hpp>

#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

namespace pointhaptics {

namespace {

constexpr double unlimited = std::numeric_limits<double>::infinity();

double meminfo_available() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key, unit;
  double kb = 0;
  while (meminfo >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024;
  return unlimited;
}

// RLIMIT_AS counts the address space, so what is left is the limit less what the process maps already
double address_space_left() {
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return unlimited;
  std::ifstream statm("/proc/self/statm");
  double pages = 0;
  statm >> pages;
  const double mapped = pages * static_cast<double>(sysconf(_SC_PAGESIZE));
  return static_cast<double>(limit.rlim_cur) - mapped;
}

double read_number(const std::string& path) {
  std::ifstream in(path);
  std::string text;
  if (!(in >> text) || text == "max") return unlimited;
  try {
    return std::stod(text);
  } catch (...) {
    return unlimited;
  }
}

// cgroup v2: the process's group (/proc/self/cgroup's "0::/path") and its parents each may cap memory
double cgroup_left() {
  std::ifstream groups("/proc/self/cgroup");
  std::string line, path;
  while (std::getline(groups, line))
    if (line.rfind("0::", 0) == 0) path = line.substr(3);
  if (path.empty()) return unlimited;
  double left = unlimited;
  for (;;) {
    const std::string dir = "/sys/fs/cgroup" + (path == "/" ? std::string() : path);
    const double max = read_number(dir + "/memory.max");
    if (std::isfinite(max)) {
      const double current = read_number(dir + "/memory.current");
      left = std::min(left, max - (std::isfinite(current) ? current : 0.0));
    }
    if (path == "/" || path.empty()) break;
    const auto slash = path.find_last_of('/');
    path = slash == 0 ? "/" : path.substr(0, slash);
  }
  return left;
}

}  // namespace

MemoryLimit memory_limit() {
  MemoryLimit limit{meminfo_available(), "the memory available"};
  const double address_space = address_space_left();
  if (address_space < limit.bytes) limit = {address_space, "the process's address-space limit (ulimit -v)"};
  const double cgroup = cgroup_left();
  if (cgroup < limit.bytes) limit = {cgroup, "its control group's memory limit (memory.max)"};
  limit.bytes = std::max(0.0, limit.bytes);
  return limit;
}

}  // namespace pointhaptics
