#include "swarmbox/swarm/flock_metrics.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <numeric>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {

namespace {

constexpr double kMovingSpeed_m_s = 0.1;  // slower drones have no heading to align

// Union-find over drone indices: the groups of drones linked within link range.
class LinkedGroups {
 public:
  explicit LinkedGroups(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), std::size_t{0}); }
  void Link(std::size_t i, std::size_t j) { parent_[Find(i)] = Find(j); }
  int Count() {
    int groups = 0;
    for (std::size_t i = 0; i < parent_.size(); ++i) groups += Find(i) == i ? 1 : 0;
    return groups;
  }

 private:
  std::size_t Find(std::size_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  std::vector<std::size_t> parent_;
};

// Cosine of the angle between two horizontal velocities; 0 when either drone barely moves.
double HeadingAlignment(const Eigen::Vector3d& a_m_s, const Eigen::Vector3d& b_m_s) {
  const Eigen::Vector2d vi = a_m_s.head<2>();
  const Eigen::Vector2d vj = b_m_s.head<2>();
  if (vi.norm() > kMovingSpeed_m_s && vj.norm() > kMovingSpeed_m_s) return vi.dot(vj) / (vi.norm() * vj.norm());
  return 0.0;
}

}  // namespace

FlockMetrics ComputeFlockMetrics(std::span<const Eigen::Vector3d> positions_m,
                                 std::span<const Eigen::Vector3d> velocities_m_s,
                                 const FlockMetricsParams& params) {
  SWARMBOX_CHECK(positions_m.size() == velocities_m_s.size());
  FlockMetrics m;
  const std::size_t n = positions_m.size();
  if (n < 2) return m;
  LinkedGroups groups(n);
  std::vector<double> nearest(n, std::numeric_limits<double>::infinity());
  std::size_t pairs = 0;
  std::size_t safe_pairs = 0;
  double order_sum = 0.0;
  m.min_distance_m = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const double d = (positions_m[i] - positions_m[j]).norm();
      ++pairs;
      if (d >= params.separation_m) ++safe_pairs;
      m.min_distance_m = std::min(m.min_distance_m, d);
      nearest[i] = std::min(nearest[i], d);
      nearest[j] = std::min(nearest[j], d);
      order_sum += HeadingAlignment(velocities_m_s[i], velocities_m_s[j]);
      if (d <= params.link_range_m) groups.Link(i, j);
    }
  }
  m.safety = static_cast<double>(safe_pairs) / static_cast<double>(pairs);
  m.order = order_sum / static_cast<double>(pairs);
  m.components = groups.Count();
  m.union_ = 1.0 - static_cast<double>(m.components - 1) / static_cast<double>(n - 1);
  m.mean_nearest_m = std::accumulate(nearest.begin(), nearest.end(), 0.0) / static_cast<double>(n);
  m.max_nearest_m = *std::max_element(nearest.begin(), nearest.end());
  return m;
}

std::optional<LogEvent> FlockMetricsLog::Sample(double t_s, std::string_view node,
                                                std::span<const RosterEntry> roster) {
  if (due_s_ && t_s < *due_s_) return std::nullopt;
  due_s_ = due_s_ ? *due_s_ + period_s_ : t_s + period_s_;
  while (*due_s_ <= t_s) *due_s_ += period_s_;  // a long gap: the next on the period's grid
  if (tracks_.size() < roster.size()) tracks_.resize(roster.size());
  positions_m_.clear();
  velocities_m_s_.clear();
  for (std::size_t i = 0; i < roster.size(); ++i) {
    const RosterEntry& e = roster[i];
    Track& track = tracks_[i];
    if (track.name != e.name) track = Track{e.name};  // another member in this slot: start afresh
    const double word_t_s = t_s - e.age_s;
    if (track.seen && word_t_s > track.word_t_s + 1e-6) {
      track.velocity_m_s = (e.position_m - track.position_m) / (word_t_s - track.word_t_s);
    }
    if (!track.seen || word_t_s > track.word_t_s + 1e-6) {
      track.word_t_s = word_t_s;
      track.position_m = e.position_m;
      track.seen = true;
    }
    if (e.age_s > max_age_s_) continue;  // gone (the leader's member timeout)
    positions_m_.emplace_back(e.position_m.x(), e.position_m.y(), 0.0);
    velocities_m_s_.emplace_back(track.velocity_m_s.x(), track.velocity_m_s.y(), 0.0);
  }
  if (positions_m_.size() < 2) return std::nullopt;
  const FlockMetrics m = ComputeFlockMetrics(positions_m_, velocities_m_s_, params_);
  LogEvent line(t_s, node, "flock_metrics");
  line.Add("members", static_cast<std::int64_t>(positions_m_.size()))
      .Add("order", m.order, 3)
      .Add("safety", m.safety, 3)
      .Add("union", m.union_, 3)
      .Add("components", m.components)
      .Add("min_m", m.min_distance_m, 2)
      .Add("mean_nearest_m", m.mean_nearest_m, 2);
  return line;
}

}  // namespace swarmbox::swarm
