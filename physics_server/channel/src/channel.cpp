#include "swarmbox/channel/channel.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>
#include <utility>

#include "detail/counter_rng.hpp"

namespace swarmbox::channel {
namespace {

using detail::DrawHash;
using detail::Purpose;
using detail::PurposeCode;

constexpr double kSpeedOfLightM_S = 299792458.0;
constexpr std::uint64_t kNoReceiver = ~0ULL;

double Distance(const Vec3d& a, const Vec3d& b) {
  const double dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

std::int64_t CellIndex(double v, double size) { return static_cast<std::int64_t>(std::floor(v / size)); }

std::uint64_t CellHash(const Vec3d& p, double size) {
  std::uint64_t h = detail::SplitMix64(static_cast<std::uint64_t>(CellIndex(p.x, size)));
  h = detail::SplitMix64(h ^ static_cast<std::uint64_t>(CellIndex(p.y, size)));
  return detail::SplitMix64(h ^ static_cast<std::uint64_t>(CellIndex(p.z, size)));
}

// Heap orders (std::push_heap builds a max-heap: "a after b" makes the earliest the top).
bool EgressAfter(std::int64_t at_a, const Packet& a, std::uint32_t copy_a, std::int64_t at_b, const Packet& b,
                 std::uint32_t copy_b) {
  return std::tie(at_a, a.from, a.seq, copy_a) > std::tie(at_b, b.from, b.seq, copy_b);
}

bool DeliveryBefore(const Delivery& a, const Delivery& b) {
  return std::tie(a.at_ns, a.packet.from, a.packet.seq, a.to) < std::tie(b.at_ns, b.packet.from, b.packet.seq, b.to);
}

std::int64_t NsFromSeconds(double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); }

}  // namespace

bool SegmentCrossesBox(const Vec3d& a_in, const Vec3d& b_in, const Box& box) {
  Vec3d a = a_in, b = b_in;
  if (box.yaw_rad != 0) {
    // Into the box's frame: turn both ends by -yaw about the box's vertical centre line.
    const double cx = 0.5 * (box.min.x + box.max.x), cy = 0.5 * (box.min.y + box.max.y);
    const double c = std::cos(-box.yaw_rad), s = std::sin(-box.yaw_rad);
    auto turn = [&](Vec3d& p) {
      const double x = p.x - cx, y = p.y - cy;
      p.x = cx + c * x - s * y;
      p.y = cy + s * x + c * y;
    };
    turn(a);
    turn(b);
  }
  double t0 = 0.0, t1 = 1.0;
  const double lo[3] = {box.min.x, box.min.y, box.min.z};
  const double hi[3] = {box.max.x, box.max.y, box.max.z};
  const double pa[3] = {a.x, a.y, a.z};
  const double d[3] = {b.x - a.x, b.y - a.y, b.z - a.z};
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-12) {
      if (pa[i] < lo[i] || pa[i] > hi[i]) return false;
      continue;
    }
    double tn = (lo[i] - pa[i]) / d[i], tf = (hi[i] - pa[i]) / d[i];
    if (tn > tf) std::swap(tn, tf);
    t0 = std::max(t0, tn);
    t1 = std::min(t1, tf);
    if (t0 > t1) return false;
  }
  return true;
}

namespace {

// The first problem of an impairment: (key, message), or nullopt.
std::optional<std::pair<const char*, std::string>> ImpairmentProblem(const Impairment& m) {
  if (m.distribution != "normal" && m.distribution != "uniform") {
    return std::make_pair("distribution", "the simulated channel does not support jitter distribution '" +
                                              m.distribution + "' (supported: normal, uniform)");
  }
  if (!(m.delay_ms >= 0) || !std::isfinite(m.delay_ms)) return std::make_pair("delay_ms", std::string("delay_ms must be at least 0"));
  if (!(m.jitter_ms >= 0) || !std::isfinite(m.jitter_ms)) return std::make_pair("jitter_ms", std::string("jitter_ms must be at least 0"));
  if (!(m.loss >= 0 && m.loss <= 1)) return std::make_pair("loss", std::string("loss must be in [0, 1]"));
  if (!(m.duplicate >= 0 && m.duplicate <= 1)) return std::make_pair("duplicate", std::string("duplicate must be in [0, 1]"));
  if (!(m.rate_kbit >= 0) || !std::isfinite(m.rate_kbit)) return std::make_pair("rate_kbit", std::string("rate_kbit must be at least 0"));
  return std::nullopt;
}

}  // namespace

Status ValidateImpairment(const Impairment& m) {
  if (auto p = ImpairmentProblem(m)) return Error(ErrorCode::kInvalidArgument, std::move(p->second));
  return Ok{};
}

Result<Impairment> ReadImpairmentKeys(const yaml::Node& node, const std::string& what) {
  Impairment m;
  yaml::MapReader r(node, what);
  r.Optional("delay_ms", &m.delay_ms)
      .Optional("jitter_ms", &m.jitter_ms)
      .Optional("distribution", &m.distribution)
      .Optional("loss", &m.loss)
      .Optional("rate_kbit", &m.rate_kbit)
      .Optional("duplicate", &m.duplicate);
  if (auto s = r.Finish(); !s) return s.error();
  return m;
}

Result<Impairment> ParseImpairment(const yaml::Node& node) {
  Result<Impairment> read = ReadImpairmentKeys(node, "impairment");
  if (!read) return read.error();
  const Impairment& m = *read;
  if (auto p = ImpairmentProblem(m)) {
    const yaml::Node* at = node.Find(p->first);
    return Error(ErrorCode::kInvalidArgument, std::move(p->second), at != nullptr ? at->Where() : node.Where());
  }
  return m;
}

Channel::Channel(RadioProfile profile, std::size_t drone_count, std::uint64_t seed, std::vector<Box> obstacles)
    : profile_(std::move(profile)),
      drones_(drone_count),
      seed_(seed),
      obstacles_(std::move(obstacles)),
      positions_(drone_count),
      cells_(drone_count),
      shadow_memo_(drone_count * (drone_count > 0 ? drone_count - 1 : 0) / 2),
      senders_(drone_count),
      blocked_(drone_count * drone_count, false) {
  if (auto s = ValidateRadioProfile(profile_); !s) {
    std::fprintf(stderr, "swarmbox: channel: %s\n", s.error().ToString().c_str());
  }
  SWARMBOX_CHECK(ValidateRadioProfile(profile_).ok());
  for (SenderState& s : senders_) s.ring.resize(profile_.queue_frames);
  std::fill(cells_.begin(), cells_.end(), CellHash(Vec3d{}, profile_.path_loss.decorrelation_m));
  pending_.reserve(drone_count * 4);
  deliveries_.reserve(drone_count * drone_count);
}

void Channel::SetPositions(std::span<const Vec3d> positions_m) {
  SWARMBOX_CHECK(positions_m.size() == drones_);
  std::copy(positions_m.begin(), positions_m.end(), positions_.begin());
  for (std::size_t i = 0; i < drones_; ++i) cells_[i] = CellHash(positions_[i], profile_.path_loss.decorrelation_m);
}

void Channel::SetImpairment(std::optional<std::size_t> sender, const Impairment& impairment) {
  SWARMBOX_CHECK(ValidateImpairment(impairment).ok());
  if (sender) {
    SWARMBOX_CHECK(*sender < drones_);
    senders_[*sender].impairment = impairment;
  } else {
    default_impairment_ = impairment;
  }
}

void Channel::ClearImpairment(std::optional<std::size_t> sender) {
  if (sender) {
    SWARMBOX_CHECK(*sender < drones_);
    senders_[*sender].impairment.reset();
  } else {
    default_impairment_.reset();
  }
}

void Channel::SetBlocked(std::size_t from, std::size_t to, bool blocked) {
  SWARMBOX_CHECK(from < drones_ && to < drones_);
  blocked_[from * drones_ + to] = blocked;
}

void Channel::SetOut(std::size_t drone, bool out) {
  SWARMBOX_CHECK(drone < drones_);
  senders_[drone].out = out;
}

const Impairment* Channel::ImpairmentOf(std::size_t sender) const {
  const SenderState& s = senders_[sender];
  if (s.impairment) return &*s.impairment;
  return default_impairment_ ? &*default_impairment_ : nullptr;
}

std::int64_t Channel::AirtimeNs(std::uint32_t size_bytes) const {
  const double s = static_cast<double>(size_bytes) * 8.0 / profile_.data_rate_bps + profile_.frame_overhead_us * 1e-6;
  return std::max<std::int64_t>(1, NsFromSeconds(s));
}

void Channel::Send(std::int64_t now_ns, const Packet& p) {
  SWARMBOX_CHECK(p.from < drones_);
  SWARMBOX_CHECK(!p.to || *p.to < drones_);
  SWARMBOX_CHECK(now_ns >= watermark_ns_);
  ++stats_.sent;
  SenderState& s = senders_[p.from];
  if (s.out) {
    ++stats_.lost_out;
    return;
  }
  const Impairment* imp = ImpairmentOf(p.from);
  std::uint32_t copies = 1;
  std::int64_t base_ns = now_ns;
  if (imp != nullptr) {
    copies = ImpairedCopies(now_ns, p, *imp, s, &base_ns);
    if (copies == 0) return;
  }
  for (std::uint32_t copy = 0; copy < copies; ++copy) {
    pending_.push_back(Egress{EgressNs(base_ns, p, imp, copy), copy, p});
    std::push_heap(pending_.begin(), pending_.end(), [](const Egress& a, const Egress& b) {
      return EgressAfter(a.egress_ns, a.packet, a.copy, b.egress_ns, b.packet, b.copy);
    });
  }
}

std::uint32_t Channel::ImpairedCopies(std::int64_t now_ns, const Packet& p, const Impairment& imp, SenderState& s,
                                      std::int64_t* base_ns) {
  auto draw = [&](std::uint64_t purpose) {
    return detail::Uniform01(DrawHash(seed_, purpose, p.from, p.seq, p.sent_ns, kNoReceiver));
  };
  std::uint32_t copies = 1;
  // netem_enqueue: a duplicate adds a copy, a loss takes one away.
  if (imp.duplicate > 0 && draw(PurposeCode(Purpose::kDuplicate)) < imp.duplicate) ++copies;
  if (imp.loss > 0 && draw(PurposeCode(Purpose::kLoss)) < imp.loss) --copies;
  if (copies == 0) {
    ++stats_.lost_impairment;
    return 0;
  }
  if (copies == 2) ++stats_.duplicated;
  if (imp.rate_kbit > 0) {
    const double tx_s = static_cast<double>(p.size_bytes) * 8.0 / (imp.rate_kbit * 1000.0);
    s.serialiser_free_ns = std::max(now_ns, s.serialiser_free_ns) + NsFromSeconds(tx_s);
    *base_ns = s.serialiser_free_ns;
  }
  return copies;
}

std::int64_t Channel::EgressNs(std::int64_t base_ns, const Packet& p, const Impairment* imp, std::uint32_t copy) const {
  std::int64_t at_ns = base_ns;
  if (imp != nullptr) {
    double delay_ms = imp->delay_ms;
    if (imp->jitter_ms > 0) {
      const std::uint64_t h = DrawHash(seed_, PurposeCode(Purpose::kJitter, copy), p.from, p.seq, p.sent_ns, kNoReceiver);
      delay_ms += imp->distribution == "uniform" ? imp->jitter_ms * (2.0 * detail::Uniform01(h) - 1.0)
                                                 : imp->jitter_ms * detail::StandardNormal(h);
    }
    at_ns += NsFromSeconds(std::max(0.0, delay_ms) * 1e-3);
  }
  if (profile_.access_wait_max_us > 0) {
    const double wait = detail::Uniform01(
        DrawHash(seed_, PurposeCode(Purpose::kAccessWait, copy), p.from, p.seq, p.sent_ns, kNoReceiver));
    at_ns += NsFromSeconds(wait * profile_.access_wait_max_us * 1e-6);
  }
  return at_ns;
}

void Channel::Admit(const Egress& e) {
  SenderState& s = senders_[e.packet.from];
  if (s.out) {
    ++stats_.lost_out;
    return;
  }
  if (s.count == s.ring.size()) {
    ++stats_.lost_queue;
    return;
  }
  s.ring[(s.head + s.count) % s.ring.size()] = e;
  ++s.count;
  ++queued_;
}

void Channel::AdvanceMedium(std::int64_t until_ns) {
  auto pop_pending = [this]() {
    std::pop_heap(pending_.begin(), pending_.end(), [](const Egress& a, const Egress& b) {
      return EgressAfter(a.egress_ns, a.packet, a.copy, b.egress_ns, b.packet, b.copy);
    });
    Egress e = pending_.back();
    pending_.pop_back();
    return e;
  };
  while (true) {
    if (queued_ == 0) {
      if (pending_.empty() || pending_.front().egress_ns >= until_ns) break;
      const Egress e = pop_pending();
      medium_free_ns_ = std::max(medium_free_ns_, e.egress_ns);
      Admit(e);
      continue;
    }
    // The medium is free at medium_free_ns_: first every frame that joined its queue by then.
    if (!pending_.empty() && pending_.front().egress_ns <= medium_free_ns_) {
      Admit(pop_pending());
      continue;
    }
    if (medium_free_ns_ >= until_ns) break;
    std::size_t i = next_sender_;
    while (senders_[i].count == 0) i = (i + 1) % drones_;
    SenderState& s = senders_[i];
    const Egress e = s.ring[s.head];
    s.head = (s.head + 1) % s.ring.size();
    --s.count;
    --queued_;
    next_sender_ = (i + 1) % drones_;
    if (s.out) {
      ++stats_.lost_out;
      continue;
    }
    Transmit(medium_free_ns_, e);
  }
}

void Channel::Transmit(std::int64_t start_ns, const Egress& e) {
  const std::int64_t airtime = AirtimeNs(e.packet.size_bytes);
  const std::int64_t hold = std::max(
      airtime, NsFromSeconds(static_cast<double>(e.packet.size_bytes) * 8.0 / profile_.capacity_bps));
  medium_free_ns_ = start_ns + hold;
  stats_.medium_busy_ns += hold;
  ++stats_.transmitted;
  const std::int64_t end_ns = start_ns + airtime;
  if (e.packet.to) {
    if (*e.packet.to != e.packet.from) Receive(end_ns, e, *e.packet.to);
    return;
  }
  for (std::size_t to = 0; to < drones_; ++to) {
    if (to != e.packet.from) Receive(end_ns, e, to);
  }
}

void Channel::Receive(std::int64_t end_ns, const Egress& e, std::size_t to) {
  const std::size_t from = e.packet.from;
  if (senders_[to].out) {
    ++stats_.lost_out;
    return;
  }
  if (blocked_[from * drones_ + to]) {
    ++stats_.lost_partition;
    return;
  }
  const double d = Distance(positions_[from], positions_[to]);
  if (d > profile_.max_range_m) {
    ++stats_.lost_range;
    return;
  }
  const LinkState link = Link(from, to);
  if (link.per > 0) {
    const std::uint64_t h =
        DrawHash(seed_, PurposeCode(Purpose::kPer, e.copy), from, e.packet.seq, e.packet.sent_ns, to);
    if (detail::Uniform01(h) < link.per) {
      ++stats_.lost_per;
      return;
    }
  }
  ++stats_.delivered;
  deliveries_.push_back(Delivery{to, end_ns + NsFromSeconds(d / kSpeedOfLightM_S), e.packet});
}

void Channel::TakeDeliveries(std::int64_t until_ns, std::vector<Delivery>* out) {
  AdvanceMedium(until_ns);
  watermark_ns_ = std::max(watermark_ns_, until_ns);
  // The in-flight deliveries are few (those of the last airtime or so): partition, then sort the
  // due ones. Deliveries equal in the sort key are equal in content (a duplicate's twin).
  const auto due_end = std::partition(deliveries_.begin(), deliveries_.end(),
                                      [until_ns](const Delivery& d) { return d.at_ns <= until_ns; });
  const auto first = static_cast<std::ptrdiff_t>(out->size());
  out->insert(out->end(), deliveries_.begin(), due_end);
  deliveries_.erase(deliveries_.begin(), due_end);
  std::sort(out->begin() + first, out->end(), DeliveryBefore);
}

double Channel::ShadowingDb(std::size_t a, std::size_t b) const {
  const PathLossModel& m = profile_.path_loss;
  if (m.shadowing_sigma_db <= 0 || a == b) return 0.0;
  const std::size_t lo = std::min(a, b), hi = std::max(a, b);
  // A pure function of (seed, pair, cells); the memo only saves recomputing it.
  ShadowMemo& memo = shadow_memo_[hi * (hi - 1) / 2 + lo];
  if (memo.valid && memo.cell_lo == cells_[lo] && memo.cell_hi == cells_[hi]) return memo.db;
  const std::uint64_t h = DrawHash(seed_, PurposeCode(Purpose::kShadowing), lo, cells_[lo],
                                   static_cast<std::int64_t>(cells_[hi]), hi);
  memo = ShadowMemo{cells_[lo], cells_[hi], m.shadowing_sigma_db * detail::StandardNormal(h), true};
  return memo.db;
}

int Channel::ObstaclesBetween(const Vec3d& a, const Vec3d& b) const {
  int n = 0;
  for (const Box& box : obstacles_) n += SegmentCrossesBox(a, b, box) ? 1 : 0;
  return n;
}

LinkState Channel::Link(std::size_t from, std::size_t to) const {
  SWARMBOX_CHECK(from < drones_ && to < drones_);
  LinkState l;
  l.distance_m = Distance(positions_[from], positions_[to]);
  l.in_range = l.distance_m <= profile_.max_range_m;
  l.shadowing_db = ShadowingDb(from, to);
  l.obstacles = ObstaclesBetween(positions_[from], positions_[to]);
  l.path_loss_db = MedianPathLossDb(profile_, l.distance_m) + l.shadowing_db + profile_.obstacle_loss_db * l.obstacles;
  l.snr_db = SnrDb(profile_, l.path_loss_db);
  l.per = l.in_range ? PacketErrorRate(profile_.per, l.snr_db) : 1.0;
  return l;
}

}  // namespace swarmbox::channel
