#include <pointhaptics/core/stoppable_call.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

namespace pointhaptics {
namespace {

std::atomic<int> abandoned{0};

// what the caller and the call's thread share: the call's thread keeps it alive after an abandonment
struct CallState {
  std::mutex mutex;
  std::condition_variable done_signal;
  bool done = false, left = false;  // the call ended; the caller stopped waiting for it
  std::exception_ptr error;
};

}  // namespace

void call_stoppable(const char* where, std::function<void()> work, double expected_s) {
  throw_if_stop_requested(where);
  const auto start = std::chrono::steady_clock::now();
  std::optional<Progress> progress;
  if (expected_s > 0) progress.emplace(where, 1.0);
  auto state = std::make_shared<CallState>();
  std::thread thread([state, work = std::move(work)]() mutable {
    std::exception_ptr error;
    try {
      work();
    } catch (...) {
      error = std::current_exception();
    }
    work = nullptr;  // what the call owned is freed on this thread, even when nobody waits any more
    const std::lock_guard lock(state->mutex);
    state->error = error;
    state->done = true;
    if (state->left) abandoned.fetch_sub(1, std::memory_order_relaxed);
    state->done_signal.notify_all();
  });
  {
    std::unique_lock lock(state->mutex);
    while (!state->done_signal.wait_for(lock, std::chrono::milliseconds(5), [&] { return state->done; })) {
      if (stop_requested()) {
        state->left = true;
        abandoned.fetch_add(1, std::memory_order_relaxed);
        lock.unlock();
        thread.detach();
        throw Interrupted(std::string("interrupted during ") + where);
      }
      if (progress) {
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        progress->reach(std::min(0.99, elapsed / expected_s));
      }
    }
  }
  thread.join();
  if (state->error) std::rethrow_exception(state->error);
}

void destroy_in_background(std::function<void()> destroy) {
  abandoned.fetch_add(1, std::memory_order_relaxed);
  std::thread([destroy = std::move(destroy)]() mutable {
    destroy();
    destroy = nullptr;
    abandoned.fetch_sub(1, std::memory_order_relaxed);
  }).detach();
}

int abandoned_work_running() noexcept { return abandoned.load(std::memory_order_relaxed); }

}  // namespace pointhaptics
