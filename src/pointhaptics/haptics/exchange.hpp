#pragma once
/// @file Lock-free exchange between one producer thread and one consumer thread: the latest value (a
/// triple buffer) or a bounded stream (a ring).
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

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
  void publish() {
    back_ = middle_.exchange(static_cast<std::uint8_t>(back_ | fresh), std::memory_order_acq_rel) & index;
  }

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
  std::uint8_t back_ = 0, front_ = 1;  // owned by one side each
  alignas(64) std::atomic<std::uint8_t> middle_{2};
};

/// A bounded queue from one producer thread to one consumer thread (a ring of `capacity` slots, rounded up
/// to a power of two): push() never waits and never allocates (false when full: the caller counts the
/// loss), pop() takes the oldest value. For streams that must not be lost while the consumer keeps up, e.g.
/// the haptic log, written to a file by the simulation thread.
template <class T>
class SpscRing {
 public:
  explicit SpscRing(std::size_t capacity = 0) : slots_(round_up(capacity)), mask_(slots_.size() - 1) {}
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  std::size_t capacity() const { return slots_.size() > 1 ? slots_.size() : 0; }
  /// Producer: false if the ring is full (or has no capacity).
  bool push(const T& value) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (capacity() == 0 || head - tail_.load(std::memory_order_acquire) >= slots_.size()) return false;
    slots_[head & mask_] = value;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }
  /// Consumer: the oldest value into `out`; false if the ring is empty.
  bool pop(T& out) {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    out = slots_[tail & mask_];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

 private:
  static std::size_t round_up(std::size_t n) {
    std::size_t size = 1;
    while (size < n) size *= 2;
    return size;
  }
  std::vector<T> slots_;
  std::size_t mask_;
  alignas(64) std::atomic<std::size_t> head_{0};  // written by the producer
  alignas(64) std::atomic<std::size_t> tail_{0};  // written by the consumer
};

}  // namespace pointhaptics
