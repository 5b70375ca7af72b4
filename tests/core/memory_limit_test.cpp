// The memory a run may still take: the machine's, the process's address-space limit and its cgroup's (issue 52).
#include <pointhaptics/core/memory_limit.hpp>

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>

using namespace pointhaptics;

TEST(MemoryLimit, IsPositiveAndNamesWhatBinds) {
  const MemoryLimit limit = memory_limit();
  EXPECT_GT(limit.bytes, 0);
  EXPECT_FALSE(limit.what.empty());
}

TEST(MemoryLimit, HonoursTheProcessAddressSpaceLimit) {
  // in a child, so that the limit does not reach this test program: `ulimit -v` of what is mapped + 256 MB
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const MemoryLimit before = memory_limit();
    long pages = 0;
    if (FILE* statm = std::fopen("/proc/self/statm", "r")) {
      if (std::fscanf(statm, "%ld", &pages) != 1) pages = 0;
      std::fclose(statm);
    }
    const double mapped = static_cast<double>(pages) * static_cast<double>(sysconf(_SC_PAGESIZE));
    rlimit limit{};
    limit.rlim_cur = limit.rlim_max = static_cast<rlim_t>(mapped + 256e6);
    if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(3);
    const MemoryLimit after = memory_limit();
    const bool names = after.what.find("ulimit -v") != std::string::npos;
    const bool near = std::abs(after.bytes - 256e6) < 64e6;
    _exit(!(before.bytes > after.bytes) ? 4 : !names ? 5 : !near ? 6 : 0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "3: setrlimit failed, 4: no lower, 5: not named, 6: not the limit left";
}
