#pragma once
/// @file Stopping and watching long work from outside. One process-wide stop request (set by a signal handler,
/// Python's Ctrl-C, a button) that every long loop polls through its Progress, and one optional sink that the
/// same polls feed, so that whatever loop the time goes in can be stopped within 0.1 s and shown on a progress bar.
#include <pointhaptics/core/error.hpp>

#include <atomic>
#include <string>

namespace pointhaptics {

/// Thrown by a loop that finds a stop requested. Not a failure of the input: the caller keeps what was reached
/// (a step interrupted in its middle leaves the state at its last consistent point: see Simulation::run).
class Interrupted : public Error {
 public:
  using Error::Error;
};

/// Ask every running computation to stop at its next poll. Async-signal-safe (one lock-free store).
void request_stop() noexcept;
/// Forget a stop request (before a new run, or once an interruption was handled).
void clear_stop_request() noexcept;
bool stop_requested() noexcept;
/// Throw Interrupted naming `where` if a stop was requested.
void throw_if_stop_requested(const char* where);

/// Told where long work is. Called from any thread the work runs on, at most every 50 ms, never concurrently.
class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  /// `phase` names the work ("neighbour search"); `fraction` in [0, 1] is its share done.
  virtual void progress(const char* phase, double fraction) = 0;
  /// The phase is over (its last progress() may have been below 1).
  virtual void finished(const char* /*phase*/) {}
  /// Work expected to be long is about to start: `message` says what and how long (one line, no newline).
  virtual void announce(const std::string& /*message*/) {}
};
/// The phase whose progress is the share of a step done: a long explicit step's sub-steps (other phases inside a
/// step, a sparse factorisation, are parts of it of unknown share).
inline constexpr const char* substep_phase = "explicit sub-steps";
/// The sink every Progress reports to (nullptr: none, the default). The caller keeps it alive while set.
void set_progress_sink(ProgressSink* sink) noexcept;
/// Tell the sink, if any, that long work starts (a set-up estimated to take more than 2 s).
void announce(const std::string& message);
/// Seconds as a person reads them: "40 s", "12 min", "25 h".
std::string format_duration(double seconds);

/// A long loop's poll: made once before the loop with the amount of work, advanced from any thread as it goes.
/// advance() throws Interrupted if a stop was requested and tells the sink (rate-limited). Cheap enough to call
/// per point of set-up work or per iteration of a solver (one relaxed atomic add and load); not meant for the
/// step's force loops, which poll once per sub-step or iteration.
class Progress {
 public:
  Progress(const char* phase, double total);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  void advance(double amount = 1);
  /// Set the amount done (for loops that know it, e.g. sub-step k of n).
  void reach(double done);

 private:
  void report(double done);
  const char* phase_;
  double total_;
  std::atomic<double> done_{0};
};

}  // namespace pointhaptics
