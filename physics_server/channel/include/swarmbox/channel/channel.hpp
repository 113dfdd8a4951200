// Channel: the simulated radio channel of a trial (radio.model channel, issue #17). Pure: no DDS,
// no ODE, no clock, no threads. The physics server owns one, tells it where the drones are, hands
// it every frame the agents send with the step's simulated send time, and takes the deliveries due
// by each step's end.
//
// The model, per frame (README.md in this folder has the figures and the limits):
//  1. The sender's impairment, as netem on its egress: one loss draw, one duplicate draw, a delay of
//     delay_ms + a jitter draw (normal or uniform) per copy; rate_kbit as a per-sender serialiser.
//     Then, for TDM radios, a uniform wait for the sender's slot (profile access_wait_max_us).
//  2. The shared medium: one for all drones. Each sender has a FIFO of queue_frames (a full queue
//     drops the frame); the medium serves the queues round-robin by sender, one frame at a time,
//     each holding it max(airtime, size*8/capacity_bps), airtime = size*8/data_rate + overhead.
//  3. Per receiver (every other drone for a broadcast, the addressee for a unicast): nothing
//     beyond max_range_m; log-distance path loss + seeded shadowing + obstacle_loss_db per Box the
//     line of sight crosses -> SNR -> PER (sigmoid) -> one Bernoulli draw. Delivered at the end of
//     the frame's airtime plus the propagation time d/c.
//  Partitions (SetBlocked) drop at the receiver; a drone SetOut neither sends nor hears.
//
// Determinism: every random draw comes from a counter-based generator keyed on (seed, purpose,
// from, seq, sent_ns, to): no draw depends on the order of calls for different senders. A sender's
// frames are serialised in the order of its Send calls (its seq order). State changes
// (SetPositions, SetBlocked, SetOut) apply to the medium events at or after the `until_ns` of the
// last TakeDeliveries call; the caller keeps Send's now_ns >= that until_ns (checked).
//
//   Channel ch(*profile, 3, /*seed=*/42, obstacles);
//   ch.SetPositions(positions);                       // every step, true positions
//   ch.Send(t_k, Packet{.from = 0, .seq = 1, .size_bytes = 120, .sent_ns = t_k, .token = 7});
//   std::vector<Delivery> got;
//   ch.TakeDeliveries(t_k1, &got);                    // sorted (at_ns, from, seq, to)
//
// Not thread-safe: one thread calls everything. Memory: per-sender queues are allocated once;
// the in-flight heaps grow to their high-water mark and are reused (no allocation per frame once
// warm).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "swarmbox/channel/radio_profile.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::channel {

struct Vec3d {
  double x = 0, y = 0, z = 0;
};

// An obstacle: axis-aligned in its own frame, world ENU [m]; yaw_rad turns it about the vertical
// axis through its centre (as physics::ObstacleBox).
struct Box {
  Vec3d min, max;
  double yaw_rad = 0;
};

// Whether the segment a-b crosses (or touches) the box.
bool SegmentCrossesBox(const Vec3d& a, const Vec3d& b, const Box& box);

// A sender's egress impairment, with netem's meaning (the trial's network.mesh keys).
struct Impairment {
  double delay_ms = 0;
  double jitter_ms = 0;
  std::string distribution = "normal";  // normal | uniform (pareto, paretonormal: refused)
  double loss = 0;                       // 0..1
  double rate_kbit = 0;                  // 0 = no rate limit
  double duplicate = 0;                  // 0..1
  bool operator==(const Impairment&) const = default;
};
// Ok, or why the channel cannot carry the impairment out (an unsupported distribution names the
// supported ones).
Status ValidateImpairment(const Impairment& impairment);
// Reads a netem spec mapping ({delay_ms, jitter_ms, distribution, loss, rate_kbit, duplicate}, all
// optional: the radio plan's `mesh` and `impairment` objects) and validates it. Errors carry
// file:line:col of the offending key; unknown keys (reorder_gap, corrupt...) are errors.
Result<Impairment> ParseImpairment(const yaml::Node& node);
// The keys alone, unvalidated (`what` names the mapping in errors): ParseImpairment's reading, and
// the radio plan's, which allows every netem distribution.
Result<Impairment> ReadImpairmentKeys(const yaml::Node& node, const std::string& what);

struct Packet {
  std::size_t from = 0;                  // drone index
  std::optional<std::size_t> to;         // nullopt = broadcast
  std::uint64_t seq = 0;                 // per sender
  std::uint32_t size_bytes = 0;
  std::int64_t sent_ns = 0;
  std::uint64_t token = 0;               // the caller's handle for the payload
};

struct Delivery {
  std::size_t to = 0;
  std::int64_t at_ns = 0;
  Packet packet;
};

// Counters since construction. `sent` counts Send calls; lost_impairment counts frames,
// lost_queue frame copies; delivered, lost_range, lost_per and lost_partition count (frame copy,
// receiver) pairs; lost_out counts frames or copies of an out sender and (copy, receiver) pairs of
// an out receiver.
struct ChannelStats {
  std::uint64_t sent = 0;            // Send calls
  std::uint64_t delivered = 0;       // deliveries made
  std::uint64_t lost_range = 0;      // receiver beyond max_range_m
  std::uint64_t lost_per = 0;        // the PER draw failed
  std::uint64_t lost_impairment = 0; // the sender's impairment loss
  std::uint64_t lost_queue = 0;      // the sender's medium queue was full
  std::uint64_t lost_partition = 0;  // SetBlocked(from, to)
  std::uint64_t lost_out = 0;        // sender out (sent or queued), or receiver out
  std::uint64_t duplicated = 0;      // extra copies made by the impairment
  std::uint64_t transmitted = 0;     // frames that went on the air
  std::int64_t medium_busy_ns = 0;   // total time the medium was held
};

// What the channel model says about one link now (tests, the range check, event=link).
struct LinkState {
  double distance_m = 0;
  bool in_range = false;
  double path_loss_db = 0;     // median + shadowing + obstacles
  double shadowing_db = 0;
  int obstacles = 0;           // boxes crossing the line of sight
  double snr_db = 0;
  double per = 1;              // 1 when out of range
};

class Channel {
 public:
  // `profile` must pass ValidateRadioProfile (checked). `obstacles` are static.
  Channel(RadioProfile profile, std::size_t drone_count, std::uint64_t seed, std::vector<Box> obstacles);

  // True positions now [m, ENU], one per drone (size drone_count, checked).
  void SetPositions(std::span<const Vec3d> positions_m);
  // The egress impairment of `sender`, or of every sender without its own (nullopt). The
  // impairment must pass ValidateImpairment (checked: validate user input before).
  void SetImpairment(std::optional<std::size_t> sender, const Impairment& impairment);
  // Removes the sender's own impairment (it falls back to the default), or the default (nullopt).
  void ClearImpairment(std::optional<std::size_t> sender);
  void SetBlocked(std::size_t from, std::size_t to, bool blocked);  // partitions, one way
  void SetOut(std::size_t drone, bool out);   // out of the world: sends and hears nothing

  // Hands a frame to the channel at simulated time now_ns (packet.from < drone_count, checked;
  // now_ns >= the last until_ns given to TakeDeliveries, checked).
  void Send(std::int64_t now_ns, const Packet& packet);
  // Appends every delivery with at_ns <= until_ns, sorted by (at_ns, packet.from, packet.seq, to).
  void TakeDeliveries(std::int64_t until_ns, std::vector<Delivery>* out);

  const ChannelStats& stats() const { return stats_; }
  const RadioProfile& profile() const { return profile_; }
  std::size_t drone_count() const { return drones_; }
  // The largest until_ns given to TakeDeliveries so far (the earliest time Send accepts).
  std::int64_t taken_until_ns() const { return watermark_ns_; }
  // The link from -> to at the current positions (no random draw beyond the seeded shadowing).
  LinkState Link(std::size_t from, std::size_t to) const;
  // Airtime of a frame of `size_bytes` [ns] (size*8/data_rate + overhead, at least 1 ns).
  std::int64_t AirtimeNs(std::uint32_t size_bytes) const;

 private:
  struct Egress {          // a frame copy leaving the sender's impairment at egress_ns
    std::int64_t egress_ns = 0;
    std::uint32_t copy = 0;
    Packet packet;
  };
  struct SenderState {
    std::vector<Egress> ring;  // the medium queue, capacity queue_frames
    std::size_t head = 0;
    std::size_t count = 0;
    std::int64_t serialiser_free_ns = 0;  // rate_kbit
    std::optional<Impairment> impairment;
    bool out = false;
  };

  const Impairment* ImpairmentOf(std::size_t sender) const;
  void AdvanceMedium(std::int64_t until_ns);
  void Admit(const Egress& e);
  // Send's steps: how many copies of `p` the sender's impairment lets out (0: lost; the rate
  // limit's serialiser moves *base_ns), and when copy `copy` leaves (delay, jitter, access wait).
  std::uint32_t ImpairedCopies(std::int64_t now_ns, const Packet& p, const Impairment& imp, SenderState& s,
                               std::int64_t* base_ns);
  std::int64_t EgressNs(std::int64_t base_ns, const Packet& p, const Impairment* imp, std::uint32_t copy) const;
  void Transmit(std::int64_t start_ns, const Egress& e);
  void Receive(std::int64_t end_ns, const Egress& e, std::size_t to);
  double ShadowingDb(std::size_t a, std::size_t b) const;
  int ObstaclesBetween(const Vec3d& a, const Vec3d& b) const;

  // The shadowing of an unordered pair for the cells it was drawn in (a memo of ShadowingDb).
  struct ShadowMemo {
    std::uint64_t cell_lo = 0, cell_hi = 0;
    double db = 0;
    bool valid = false;
  };

  RadioProfile profile_;
  std::size_t drones_;
  std::uint64_t seed_;
  std::vector<Box> obstacles_;
  std::vector<Vec3d> positions_;
  std::vector<std::uint64_t> cells_;      // hash of each drone's shadowing cell
  mutable std::vector<ShadowMemo> shadow_memo_;  // [hi * (hi - 1) / 2 + lo], lo < hi
  std::vector<SenderState> senders_;
  std::vector<bool> blocked_;            // drones_ x drones_, [from * drones_ + to]
  std::optional<Impairment> default_impairment_;
  std::vector<Egress> pending_;          // min-heap on (egress_ns, from, seq, copy)
  std::vector<Delivery> deliveries_;     // made, not yet taken (unordered)
  std::int64_t medium_free_ns_ = 0;
  std::size_t next_sender_ = 0;          // round-robin cursor
  std::size_t queued_ = 0;               // frames in all sender queues
  std::int64_t watermark_ns_ = std::numeric_limits<std::int64_t>::min();
  ChannelStats stats_;
};

}  // namespace swarmbox::channel
