#pragma once
/// @file The tangent's per-point linearisations, stored as plain doubles (so that Tangent is not a template),
/// and the loop over points shared by tangent.cpp and tangent_blocks.cpp.
#include <pointhaptics/core/workspace.hpp>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <cstdint>
#include <cstring>
#include <type_traits>

namespace pointhaptics::detail {

/// fn(i) for i in [0, n): on ws's threads (even contiguous ranges) when given, else on TBB's.
template <class Fn>
void for_each_point(index_t n, Workspace* ws, Fn&& fn) {
  if (ws) {
    const int chunks = ws->n_threads();
    ws->for_each_chunk([&](int c) {
      const index_t first = static_cast<index_t>(std::int64_t{n} * c / chunks);
      const index_t last = static_cast<index_t>(std::int64_t{n} * (c + 1) / chunks);
      for (index_t i = first; i < last; ++i) fn(i);
    });
    return;
  }
  tbb::parallel_for(tbb::blocked_range<index_t>(0, n, 256), [&](const tbb::blocked_range<index_t>& r) {
    for (index_t i = r.begin(); i != r.end(); ++i) fn(i);
  });
}

// A material's Linearisation per point, kept as plain doubles (so that Tangent is not a template).
template <class L>
constexpr std::size_t doubles_of = sizeof(L) / sizeof(double);

template <class L>
PH_ALWAYS_INLINE inline L load_linearisation(const double* base, index_t i) {
  // fixed-size Eigen matrices and doubles only: plain arrays of doubles
  static_assert(std::is_standard_layout_v<L> && sizeof(L) % sizeof(double) == 0);
  L at;
  std::memcpy(static_cast<void*>(&at), base + doubles_of<L> * static_cast<std::size_t>(i), sizeof(L));
  return at;
}

template <class L>
PH_ALWAYS_INLINE inline void store_linearisation(double* base, index_t i, const L& at) {
  static_assert(std::is_standard_layout_v<L> && sizeof(L) % sizeof(double) == 0);
  // Eigen's fixed-size matrices are arrays of doubles (standard layout, asserted) whose copy constructor is
  // user-provided, so they are not TriviallyCopyable by the letter; copying their bytes is what that
  // constructor does. The buffer's doubles are only 8-byte aligned, so the bytes are copied, not placed.
  double* target = base + doubles_of<L> * static_cast<std::size_t>(i);
  // NOLINTNEXTLINE(bugprone-undefined-memory-manipulation)
  std::memcpy(static_cast<void*>(target), &at, sizeof(L));
}

}  // namespace pointhaptics::detail
