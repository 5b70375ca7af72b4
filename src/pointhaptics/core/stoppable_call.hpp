#pragma once
/// @file Stopping work that cannot poll: a library call that runs for seconds without returning (CHOLMOD's
/// ordering and numeric factorisation). It runs on a thread of its own while the caller waits polling the stop
/// request; on a stop the caller leaves it to end by itself and goes on at once. Whatever the call touches must
/// therefore be owned by it (captured by value or through a shared_ptr), never borrowed from the caller.
#include <pointhaptics/core/run_control.hpp>

#include <functional>
#include <memory>

namespace pointhaptics {

/// Run `work` on its own thread and wait for it, polling the stop request every 5 ms: its exception, if any, is
/// rethrown here; on a stop the thread is abandoned (it ends by itself and frees what it owns) and Interrupted
/// is thrown naming `where`. With `expected_s` > 0 the wait is shown as progress (elapsed over expected time).
void call_stoppable(const char* where, std::function<void()> work, double expected_s = 0);

/// Destroy `owned` on a thread of its own: for an object whose destructor waits for work that cannot be stopped
/// (a worker thread in a library call), so that a stopped run does not wait for it.
void destroy_in_background(std::function<void()> destroy);
template <class T>
void destroy_in_background(std::unique_ptr<T> owned) {
  if (!owned) return;
  destroy_in_background([p = std::shared_ptr<T>(std::move(owned))]() mutable { p.reset(); });
}

/// Abandoned calls and background destructions that have not ended yet. A process about to exit with some
/// still running should leave through std::_Exit after flushing its outputs: static destructors (the BLAS's
/// buffers) must not run under them.
int abandoned_work_running() noexcept;

}  // namespace pointhaptics
