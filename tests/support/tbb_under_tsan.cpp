/// @file Linked into every test program of the ThreadSanitizer build (tests/CMakeLists.txt), and only there.
#include <oneapi/tbb/global_control.h>

namespace pointhaptics::test {
namespace {

// Debian's TBB is not instrumented, so ThreadSanitizer cannot see its joins: it reports every result a TBB loop
// hands back (the model build's neighbour rows) as a race, and a task that read its caller's stack (the loop's
// wait context) as racing with whatever the caller puts there next, which no suppression can match once TSan's
// history has lost the task's side (CI: SparseCholesky's test, random_field writing where the model build's
// loop had been). TBB's own workers are kept out of every program; the threads under test are ours (the haptic
// loop, the re-selection and factorisation workers, a stoppable call's thread, the viewer's session), and each
// still runs its TBB loops, on itself. A race inside one TBB loop shows as a result that differs between one
// thread and many, which the optimised and ASan suites check (BuildModel.TheModelAndItsEnergyAreTheSameOnOne...,
// the solvers' one-and-two-workspace-threads tests).
const tbb::global_control one_tbb_thread(tbb::global_control::max_allowed_parallelism, 1);

}  // namespace
}  // namespace pointhaptics::test
