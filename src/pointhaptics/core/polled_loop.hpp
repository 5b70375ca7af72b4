#pragma once
/// @file The set-up's per-point loops, in parallel, polled for a stop and reported as progress (run_control.hpp):
/// whatever the size of a neighbourhood, a signal is honoured within one item's work.
#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/core/types.hpp>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace pointhaptics {

/// body(i) for i in [0, n), in parallel; `phase` names the work for an interruption and the progress bar.
template <class Body>
void parallel_for_polled(const char* phase, index_t n, Body&& body) {
  Progress progress(phase, n);
  tbb::parallel_for(tbb::blocked_range<index_t>(0, n, 64), [&](const tbb::blocked_range<index_t>& range) {
    for (index_t i = range.begin(); i != range.end(); ++i) {
      throw_if_stop_requested(phase);
      body(i);
    }
    progress.advance(static_cast<double>(range.size()));
  });
}

/// v.resize(n), polled every 16M entries: zero-filling a GB-sized array (the pairs of a wide support) takes most
/// of a second, longer than a stop may wait.
template <class T>
void resize_polled(std::vector<T>& v, std::size_t n, const char* phase) {
  constexpr std::size_t chunk = std::size_t{1} << 24;
  v.reserve(n);  // no reallocation below
  while (v.size() < n) {
    throw_if_stop_requested(phase);
    v.resize(std::min(n, v.size() + chunk));
  }
  v.resize(n);
}

}  // namespace pointhaptics
