// EventRing: the bounded event queue of FlightController and OffboardFailsafe. A fixed array (no
// allocation in the control loop, STYLE.md 12); when nobody pops and it is full, the oldest
// event makes room for the newest.
//
//   EventRing<FlightEvent, 32> events;
//   events.Push(e);
//   FlightEvent out;
//   while (events.Pop(&out)) Report(out);
#pragma once

#include <array>
#include <cstddef>

namespace swarmbox::flight::detail {

template <typename Event, std::size_t kCapacity>
class EventRing {
 public:
  // Appends `e`; at capacity the oldest event is dropped first.
  void Push(const Event& e) {
    if (count_ == kCapacity) {
      head_ = (head_ + 1) % kCapacity;
      --count_;
    }
    events_[(head_ + count_) % kCapacity] = e;
    ++count_;
  }
  // The oldest event into *out; false when there is none.
  bool Pop(Event* out) {
    if (count_ == 0) return false;
    *out = events_[head_];
    head_ = (head_ + 1) % kCapacity;
    --count_;
    return true;
  }

 private:
  std::array<Event, kCapacity> events_{};
  std::size_t head_ = 0;
  std::size_t count_ = 0;
};

}  // namespace swarmbox::flight::detail
