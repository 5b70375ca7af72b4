// The stop request and the progress sink that every long loop polls (issue 52).
#include <pointhaptics/core/run_control.hpp>

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

using namespace pointhaptics;

namespace {

struct RecordingSink : ProgressSink {
  std::vector<double> fractions;
  std::vector<std::string> finished_phases, announcements;
  void progress(const char* phase, double fraction) override {
    EXPECT_STREQ(phase, "the test loop");
    fractions.push_back(fraction);
  }
  void finished(const char* phase) override { finished_phases.emplace_back(phase); }
  void announce(const std::string& message) override { announcements.push_back(message); }
};

// the sink is process-wide: each test sets and clears its own
struct SinkScope {
  explicit SinkScope(ProgressSink* sink) { set_progress_sink(sink); }
  ~SinkScope() {
    set_progress_sink(nullptr);
    clear_stop_request();
  }
};

}  // namespace

TEST(RunControl, AStopRequestThrowsInterruptedNamingTheLoopUntilCleared) {
  clear_stop_request();
  EXPECT_NO_THROW(throw_if_stop_requested("the test loop"));
  request_stop();
  EXPECT_TRUE(stop_requested());
  try {
    throw_if_stop_requested("the test loop");
    FAIL() << "no Interrupted";
  } catch (const Interrupted& e) {
    EXPECT_EQ(std::string(e.what()), "interrupted during the test loop");
  }
  // an Interrupted is an Error: whoever catches the library's errors also catches it
  EXPECT_THROW(throw_if_stop_requested("x"), Error);
  clear_stop_request();
  EXPECT_FALSE(stop_requested());
  EXPECT_NO_THROW(throw_if_stop_requested("the test loop"));
}

TEST(RunControl, ProgressIsReportedRateLimitedAndAStopEndsTheLoop) {
  RecordingSink sink;
  SinkScope scope(&sink);
  {
    Progress progress("the test loop", 40);
    for (int k = 0; k < 40; ++k) {
      progress.advance();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  // 200 ms of work told at most every 50 ms: a few reports, rising, within [0, 1]
  ASSERT_GE(sink.fractions.size(), 2u);
  EXPECT_LE(sink.fractions.size(), 6u);
  for (std::size_t k = 1; k < sink.fractions.size(); ++k) EXPECT_GT(sink.fractions[k], sink.fractions[k - 1]);
  EXPECT_GT(sink.fractions.front(), 0);
  EXPECT_LE(sink.fractions.back(), 1);
  EXPECT_EQ(sink.finished_phases, std::vector<std::string>{"the test loop"});
  // a stop requested from another thread ends the loop at its next advance
  Progress progress("the test loop", 1e9);
  std::thread stopper([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    request_stop();
  });
  long long done = 0;
  EXPECT_THROW(
      for (;;) {
        progress.advance();
        ++done;
      },
      Interrupted);
  stopper.join();
  EXPECT_GT(done, 0);
}

TEST(RunControl, AnnouncementsReachTheSinkAndDurationsReadAsAPersonReadsThem) {
  RecordingSink sink;
  {
    SinkScope scope(&sink);
    announce("setting up a lot");
  }
  announce("nobody listens");  // no sink: nothing happens
  EXPECT_EQ(sink.announcements, std::vector<std::string>{"setting up a lot"});
  EXPECT_EQ(format_duration(40), "40 s");
  EXPECT_EQ(format_duration(720), "12 min");
  EXPECT_EQ(format_duration(90000), "25.0 h");
}
