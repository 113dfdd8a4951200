// Test doubles for driving passive RaftServices in one thread on simulated time:
//   ManualClock  a raft::Clock in whole microseconds, set by the test;
//   SimRadio     an in-memory radio between named nodes: each message is delayed by
//                delay_ms +- jitter_ms (normal, truncated at 0) and lost with probability
//                `loss`, as netem does on a sender's egress. Every draw comes from SplitMix64
//                keyed on (seed, purpose, sender, the sender's message number), so the same
//                sends give the same deliveries whatever the order of the calls. Deliveries are
//                taken per receiver, sorted by (delivery time, sender, sender's number), as the
//                channel hands them to an agent.
//
//   ManualClock clock;  SimRadio radio({"a", "b"}, {.delay_ms = 100, .jitter_ms = 20,
//                                                  .loss = 0.05, .seed = 7}, clock);
//   RaftService::Start(cfg_a, radio.Endpoint(0), clock, sink);   // "a" sends through endpoint 0
//   each step: clock.Advance(4000); radio.TakeDue(0, &batch); feed batch; Tick();
// Not thread-safe (one test thread drives everything). Header-only.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <numbers>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "swarmbox/raft/node_driver.hpp"

namespace swarmbox::raft_service::testing {

class ManualClock final : public raft::Clock {
 public:
  double NowS() const override { return static_cast<double>(now_us_) * 1e-6; }
  std::int64_t now_us() const { return now_us_; }
  void Set(std::int64_t t_us) { now_us_ = t_us; }
  void Advance(std::int64_t dt_us) { now_us_ += dt_us; }

 private:
  std::int64_t now_us_ = 0;
};

struct SimLink {
  double delay_ms = 0;
  double jitter_ms = 0;  // standard deviation of the normal delay
  double loss = 0;       // 0..1, per message
  std::uint64_t seed = 1;
};

class SimRadio {
 public:
  SimRadio(std::vector<std::string> names, SimLink link, const ManualClock& clock)
      : names_(std::move(names)), link_(link), clock_(clock), pending_(names_.size()),
        next_seq_(names_.size(), 0) {
    for (std::size_t i = 0; i < names_.size(); ++i) {
      endpoints_.push_back(std::make_unique<Port>(this, i));
    }
  }

  // The raft::Transport of node `i` (its sends leave from there).
  raft::Transport& Endpoint(std::size_t i) { return *endpoints_[i]; }

  // Moves the payloads for node `to` due by the clock's now to `out`, in delivery order.
  void TakeDue(std::size_t to, std::vector<raft::Bytes>* out) {
    auto& q = pending_[to];
    const std::int64_t now = clock_.now_us();
    auto due_end = std::partition(q.begin(), q.end(), [now](const InFlight& m) { return m.at_us <= now; });
    std::sort(q.begin(), due_end, [](const InFlight& x, const InFlight& y) {
      return std::tie(x.at_us, x.from, x.seq) < std::tie(y.at_us, y.from, y.seq);
    });
    for (auto it = q.begin(); it != due_end; ++it) out->push_back(std::move(it->bytes));
    q.erase(q.begin(), due_end);
  }
  // Drops everything on its way to node `to` (a node that is out hears nothing).
  void DropPendingFor(std::size_t to) { pending_[to].clear(); }

  std::uint64_t sent() const { return sent_; }
  std::uint64_t lost() const { return lost_; }

 private:
  struct InFlight {
    std::int64_t at_us = 0;
    std::size_t from = 0;
    std::uint64_t seq = 0;
    raft::Bytes bytes;
  };
  class Port final : public raft::Transport {
   public:
    Port(SimRadio* radio, std::size_t self) : radio_(radio), self_(self) {}
    void Send(const std::string& to, std::span<const std::uint8_t> bytes) override {
      radio_->Send(self_, to, bytes);
    }

   private:
    SimRadio* radio_;
    std::size_t self_;
  };

  static std::uint64_t SplitMix64(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
  }
  // Uniform in [0, 1) from (seed, purpose, from, seq).
  double Uniform(std::uint64_t purpose, std::size_t from, std::uint64_t seq) const {
    std::uint64_t h = SplitMix64(link_.seed);
    h = SplitMix64(h ^ purpose);
    h = SplitMix64(h ^ static_cast<std::uint64_t>(from));
    h = SplitMix64(h ^ seq);
    return static_cast<double>(h >> 11) * 0x1.0p-53;
  }

  void Send(std::size_t from, const std::string& to, std::span<const std::uint8_t> bytes) {
    const auto it = std::find(names_.begin(), names_.end(), to);
    if (it == names_.end()) return;  // nobody of that name: lost in the air
    const std::uint64_t seq = next_seq_[from]++;
    ++sent_;
    if (Uniform(0, from, seq) < link_.loss) {
      ++lost_;
      return;
    }
    // Box-Muller from two independent uniforms (1 - u: never log(0)).
    const double u1 = 1.0 - Uniform(1, from, seq);
    const double u2 = Uniform(2, from, seq);
    const double z = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
    const double delay_ms = std::max(0.0, link_.delay_ms + link_.jitter_ms * z);
    const std::int64_t at = clock_.now_us() + std::llround(delay_ms * 1000.0);
    pending_[static_cast<std::size_t>(it - names_.begin())].push_back(
        {at, from, seq, raft::Bytes(bytes.begin(), bytes.end())});
  }

  std::vector<std::string> names_;
  SimLink link_;
  const ManualClock& clock_;
  std::vector<std::vector<InFlight>> pending_;  // per receiver
  std::vector<std::uint64_t> next_seq_;         // per sender
  std::vector<std::unique_ptr<Port>> endpoints_;
  std::uint64_t sent_ = 0;
  std::uint64_t lost_ = 0;
};

}  // namespace swarmbox::raft_service::testing
