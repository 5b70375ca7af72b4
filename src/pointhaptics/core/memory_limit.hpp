#pragma once
/// @file How much memory a run may still take: the least of the machine's available memory, the process's own
/// address-space limit (RLIMIT_AS, `ulimit -v`) and its cgroup's limit (memory.max), so that a run too big is
/// refused before it starts, naming the limit that binds.
#include <string>

namespace pointhaptics {

struct MemoryLimit {
  double bytes = 0;  ///< what may still be allocated, bytes (infinity when nothing could be read)
  std::string what;  ///< the limit that binds: "the memory available", "the process's limit (ulimit -v)", ...
};

/// The binding limit now (reads /proc and /sys; a few microseconds).
MemoryLimit memory_limit();

}  // namespace pointhaptics
