#include "swarmbox/report/trial_metrics.hpp"

#include <algorithm>
#include <cmath>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::report {

namespace {

std::optional<double> Number(const LogfmtFields& fields, std::string_view key) {
  if (auto v = FindField(fields, key)) return yaml::ScalarAsDouble(*v);
  return std::nullopt;
}

void KeepMin(std::optional<double>& slot, double v) {
  if (!slot || v < *slot) slot = v;
}

}  // namespace

const std::vector<std::string>& MetricNames() {
  static const std::vector<std::string> kNames = {
      "mission_time_s", "first_detection_s", "detections",   "victims_confirmed",
      "min_separation_m", "collisions",       "leader_changes", "failover_s",
      "radio_rtt_ms",   "radio_loss",        "victims_rescued", "false_alarms_rejected",
      "false_victims_confirmed", "false_victims_rescued", "victims_missed"};
  return kNames;
}

void TrialMetrics::OnLogEvent(std::string_view component, const LogfmtFields& fields) {
  const auto event = FindField(fields, "event");
  if (!event) return;
  const std::optional<double> t = Number(fields, "t");
  const std::string node = FindField(fields, "node").value_or(std::string(component));
  const std::string& e = *event;
  if (e == "mission_complete") {
    if (t) KeepMin(mission_time_s_, *t);
  } else if (e == "victim_detected" || e == "victim_confirmed" || e == "sighting_reported") {
    OnVictimEvent(e, t, fields);
  } else if (e == "victim_status") {
    // Every node logs the status as it applies the entry: distinct ids, as mission_complete's
    // `rescued` counts the mission's victims whose status is rescued.
    perception_seen_ = true;
    const auto victim = FindField(fields, "id");
    if (victim && FindField(fields, "status") == std::optional<std::string>("rescued")) {
      rescued_.insert(*victim);
    }
  } else if (e == "rejected") {
    perception_seen_ = true;
    if (const auto candidate = FindField(fields, "candidate")) rejected_.insert(*candidate);
  } else if (e == "mission_state") {
    perception_seen_ = true;  // the mission runs: zero detections is then a real zero
  } else if (e == "collision") {
    ++collisions_;
  } else if (e == "leader_elected") {
    OnLeaderElected(t, fields);
  } else if (e == "raft_stopped" || e == "stopped" || e == "crash") {
    if (t) leader_losses_.emplace_back(*t, node);
  } else if (e == "link") {
    OnLinkEvent(fields);
  }
}

void TrialMetrics::OnVictimEvent(const std::string& e, std::optional<double> t, const LogfmtFields& fields) {
  perception_seen_ = true;
  if (t) KeepMin(first_detection_s_, *t);
  // Victims are told apart by `id` (the mission's) or `victim`; a sighting names none and only
  // counts for the time of the first detection.
  auto victim = FindField(fields, "id");
  if (!victim) victim = FindField(fields, "victim");
  if (victim && e != "sighting_reported") {
    detected_.insert(*victim);
    if (e == "victim_confirmed") {
      confirmed_.insert(*victim);
      const auto x = Number(fields, "x"), y = Number(fields, "y");
      if (x && y) confirmed_at_[*victim] = {*x, *y};
    }
  } else if (e == "victim_detected") {
    ++anonymous_detections_;
  } else if (e == "victim_confirmed") {
    ++anonymous_detections_;
    ++anonymous_confirmed_;
  }
}

void TrialMetrics::OnLeaderElected(std::optional<double> t, const LogfmtFields& fields) {
  const auto term = Number(fields, "term");
  const auto leader = FindField(fields, "leader");
  if (term && leader && t) {
    const auto key = static_cast<std::int64_t>(*term);
    auto it = terms_.find(key);
    if (it == terms_.end() || *t < it->second.first) terms_[key] = {*t, *leader};
  }
}

// Weighted by the pings of each window when the line says how many (sent, received).
void TrialMetrics::OnLinkEvent(const LogfmtFields& fields) {
  const auto sent = Number(fields, "sent");
  const auto received = Number(fields, "received");
  if (auto rtt = Number(fields, "rtt_ms_mean"); rtt && std::isfinite(*rtt)) {
    const double w = received && *received > 0 ? *received : (received ? 0.0 : 1.0);
    link_rtt_sum_ += *rtt * w;
    link_rtt_w_ += w;
  }
  if (sent && received && *sent > 0) {
    link_sent_ += *sent;
    link_lost_ += std::max(0.0, *sent - *received);
  } else if (auto loss = Number(fields, "loss"); loss && std::isfinite(*loss)) {
    link_sent_ += 1;
    link_lost_ += *loss;
  }
}

void TrialMetrics::OnOrchestratorEvent(std::string_view event, std::string_view target,
                                       std::optional<double> t_s) {
  if (!t_s) return;
  const bool fault = event.find("fault") != std::string_view::npos || event == "kill" ||
                     event == "stop" || event == "pause";
  if (fault && !target.empty()) leader_losses_.emplace_back(*t_s, std::string(target));
}

void TrialMetrics::OnTruth(double t_s, std::string_view /*drone*/, double x_m, double y_m,
                           double z_m) {
  if (truth_t_ && *truth_t_ != t_s) FlushTruthTime();
  truth_t_ = t_s;
  truth_points_.push_back({x_m, y_m, z_m});
}

void TrialMetrics::FlushTruthTime() {
  for (std::size_t i = 0; i < truth_points_.size(); ++i) {
    for (std::size_t j = i + 1; j < truth_points_.size(); ++j) {
      const double dx = truth_points_[i][0] - truth_points_[j][0];
      const double dy = truth_points_[i][1] - truth_points_[j][1];
      const double dz = truth_points_[i][2] - truth_points_[j][2];
      KeepMin(min_sep_, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
  }
  truth_points_.clear();
}

MetricValues TrialMetrics::Values() {
  FlushTruthTime();
  MetricValues v;
  for (const std::string& name : MetricNames()) v[name] = std::nullopt;
  v["mission_time_s"] = mission_time_s_;
  v["first_detection_s"] = first_detection_s_;
  if (perception_seen_) PerceptionValues(&v);
  v["min_separation_m"] = min_sep_;
  if (physics_log_ || collisions_ > 0) v["collisions"] = static_cast<double>(collisions_);
  if (!terms_.empty()) LeaderValues(&v);
  if (link_rtt_w_ > 0) v["radio_rtt_ms"] = link_rtt_sum_ / link_rtt_w_;
  if (link_sent_ > 0) v["radio_loss"] = link_lost_ / link_sent_;
  return v;
}

void TrialMetrics::PerceptionValues(MetricValues* v) const {
  (*v)["detections"] = static_cast<double>(detected_.size() + anonymous_detections_);
  (*v)["victims_confirmed"] = static_cast<double>(confirmed_.size() + anonymous_confirmed_);
  (*v)["victims_rescued"] = static_cast<double>(rescued_.size());
  (*v)["false_alarms_rejected"] = static_cast<double>(rejected_.size());
  if (!world_victims_.empty()) WorldVictimValues(v);
}

// Confirmed (and rescued) where no victim of the world is, and the world's victims no rescued
// confirmation is near.
void TrialMetrics::WorldVictimValues(MetricValues* v) const {
  double false_confirmed = 0, false_rescued = 0;
  for (const auto& [id, at] : confirmed_at_) {
    double nearest = 1e300;
    for (const auto& w : world_victims_) nearest = std::min(nearest, std::hypot(at[0] - w[0], at[1] - w[1]));
    if (nearest < kFalseVictimRadiusM) continue;
    ++false_confirmed;
    if (rescued_.count(id) != 0) ++false_rescued;
  }
  (*v)["false_victims_confirmed"] = false_confirmed;
  (*v)["false_victims_rescued"] = false_rescued;
  double missed = 0;
  for (const auto& w : world_victims_) {
    bool rescued = false;
    for (const auto& [id, at] : confirmed_at_) {
      rescued = rescued || (rescued_.count(id) != 0 && std::hypot(at[0] - w[0], at[1] - w[1]) < kFalseVictimRadiusM);
    }
    missed += rescued ? 0 : 1;
  }
  (*v)["victims_missed"] = missed;
}

// Leader changes between terms, and the longest failover: from a loss of the then-current leader
// to the next election after it.
void TrialMetrics::LeaderValues(MetricValues* v) {
  int changes = 0;
  const std::string* previous = nullptr;
  for (const auto& [term, tl] : terms_) {
    if (previous != nullptr && *previous != tl.second) ++changes;
    previous = &tl.second;
  }
  (*v)["leader_changes"] = changes;
  std::sort(leader_losses_.begin(), leader_losses_.end());
  std::optional<double> longest;
  for (const auto& [t_loss, node] : leader_losses_) {
    const std::string* leader = nullptr;
    double elected_at = -1;
    for (const auto& [term, tl] : terms_) {
      if (tl.first <= t_loss && tl.first >= elected_at) {
        leader = &tl.second;
        elected_at = tl.first;
      }
    }
    if (leader == nullptr || (*leader != node && node != "raft_leader")) continue;
    std::optional<double> next;
    for (const auto& [term, tl] : terms_) {
      if (tl.first > t_loss && tl.second != node) KeepMin(next, tl.first);
    }
    if (next) {
      const double d = *next - t_loss;
      if (!longest || d > *longest) longest = d;
    }
  }
  (*v)["failover_s"] = longest;
}

}  // namespace swarmbox::report
