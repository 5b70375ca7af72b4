// Tests for core/stoppable_call: work that cannot poll (a library call) is waited for unless a stop is requested;
// then the caller goes on at once and the work ends by itself, owning what it touches.
#include <pointhaptics/core/stoppable_call.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <thread>

namespace pointhaptics {
namespace {

using namespace std::chrono_literals;

struct ClearStop {
  ~ClearStop() { clear_stop_request(); }
};

// what a blocked call owns: it runs until released, and says when it ended
struct Blocker {
  std::atomic<bool> release{false}, started{false}, ended{false};
};

void wait_for(const std::atomic<bool>& flag) {
  for (int k = 0; k < 10'000 && !flag.load(); ++k) std::this_thread::sleep_for(1ms);
  ASSERT_TRUE(flag.load());
}

// work left running is counted until it ends (released here)
void expect_counted_until_released(Blocker& blocker) {
  EXPECT_FALSE(blocker.ended.load());
  EXPECT_EQ(abandoned_work_running(), 1);
  blocker.release = true;
  wait_for(blocker.ended);
  for (int k = 0; k < 10'000 && abandoned_work_running() > 0; ++k) std::this_thread::sleep_for(1ms);
  EXPECT_EQ(abandoned_work_running(), 0);
}

TEST(StoppableCall, WaitsForTheWorkAndRethrowsItsError) {
  int result = 0;
  call_stoppable("a sum", [&result] { result = 2 + 3; });
  EXPECT_EQ(result, 5);
  EXPECT_THROW(call_stoppable("a failure", [] { throw std::runtime_error("bad input"); }), std::runtime_error);
  EXPECT_EQ(abandoned_work_running(), 0);
}

TEST(StoppableCall, AStopInsideTheWorkLeavesItToEndByItself) {
  const ClearStop clear;
  auto blocker = std::make_shared<Blocker>();
  std::thread stopper([blocker] {
    wait_for(blocker->started);
    request_stop();
  });
  try {
    call_stoppable("a library call", [blocker] {
      blocker->started = true;
      while (!blocker->release.load()) std::this_thread::sleep_for(1ms);  // never polls the stop request
      blocker->ended = true;
    });
    ADD_FAILURE() << "the stop was not honoured";
  } catch (const Interrupted& e) {
    EXPECT_STREQ(e.what(), "interrupted during a library call");
  }
  stopper.join();
  // the caller went on while the work still runs
  expect_counted_until_released(*blocker);
}

TEST(StoppableCall, ARequestMadeBeforeStartsNothing) {
  const ClearStop clear;
  request_stop();
  bool ran = false;
  EXPECT_THROW(call_stoppable("a library call", [&ran] { ran = true; }), Interrupted);
  EXPECT_FALSE(ran);
}

TEST(StoppableCall, DestroysInTheBackgroundWithoutWaiting) {
  // an object whose destructor waits (for a worker in a library call)
  struct SlowToDestroy {
    std::shared_ptr<Blocker> blocker;
    ~SlowToDestroy() {
      while (!blocker->release.load()) std::this_thread::sleep_for(1ms);
      blocker->ended = true;
    }
  };
  auto blocker = std::make_shared<Blocker>();
  auto owned = std::make_unique<SlowToDestroy>();
  owned->blocker = blocker;
  destroy_in_background(std::move(owned));
  expect_counted_until_released(*blocker);
}

}  // namespace
}  // namespace pointhaptics
