#pragma once
/// @file Include in a test program with threads of its own that also builds models with TBB.
#include <oneapi/tbb/global_control.h>

namespace pointhaptics::test {

#if defined(__SANITIZE_THREAD__)
// Debian's TBB is not instrumented, so ThreadSanitizer cannot see its joins and reports every result a TBB
// loop hands back (the model build's neighbour rows) as a race. TBB's own workers are kept out; the
// threads under test are ours (the haptic loop, the re-selection worker, the viewer's session).
inline const tbb::global_control one_tbb_thread(tbb::global_control::max_allowed_parallelism, 1);
#endif

}  // namespace pointhaptics::test
