#pragma once
/// @file Lock-free exchange of the latest value between one producer thread and one consumer thread.
#include <array>
#include <atomic>
#include <cstdint>

namespace pointhaptics {

/// A triple buffer: the producer fills back() and publish()es it; the consumer calls update() and reads
/// front(). Neither side ever waits for the other, and no value is torn: the consumer sees whole
/// published values, the latest one at the time of update(). No allocation after construction.
/// Exactly one producer thread and one consumer thread.
template <class T>
class TripleBuffer {
 public:
  explicit TripleBuffer(const T& initial = T{}) {
    for (Slot& s : slots_) s.value = initial;
  }
  TripleBuffer(const TripleBuffer&) = delete;
  TripleBuffer& operator=(const TripleBuffer&) = delete;

  /// Producer: the slot to fill (stays the producer's until publish()).
  T& back() { return slots_[back_].value; }
  /// Producer: make back() the latest value and take a free slot as the new back().
  void publish() { back_ = middle_.exchange(static_cast<std::uint8_t>(back_ | fresh), std::memory_order_acq_rel) & index; }

  /// Consumer: take the latest published value if there is a newer one than front(); true if taken.
  bool update() {
    if (!(middle_.load(std::memory_order_relaxed) & fresh)) return false;
    front_ = middle_.exchange(front_, std::memory_order_acq_rel) & index;
    return true;
  }
  /// Consumer: the value taken by the last update() (the initial value before any).
  const T& front() const { return slots_[front_].value; }

 private:
  static constexpr std::uint8_t fresh = 4, index = 3;
  struct alignas(64) Slot {
    T value;
  };
  std::array<Slot, 3> slots_;
  std::uint8_t back_ = 0, front_ = 1;          // owned by one side each
  alignas(64) std::atomic<std::uint8_t> middle_{2};
};

}  // namespace pointhaptics
