#include "swarmbox/report/trial_series.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::report {

namespace {

std::optional<double> Number(const LogfmtFields& fields, std::string_view key) {
  const auto v = FindField(fields, key);
  if (!v) return std::nullopt;
  auto d = yaml::ScalarAsDouble(*v);
  if (!d || !std::isfinite(*d)) return std::nullopt;
  return d;
}

void Add(std::map<std::string, Series>& by_name, const std::string& name, double t_s, double value) {
  Series& s = by_name[name];
  s.name = name;
  s.points.push_back({t_s, value});
}

// A state from t_s on: the open span ends there (a repeat of the same label keeps it open).
void Enter(std::map<std::string, Lane>& lanes, const std::string& name, double t_s, std::string label) {
  Lane& lane = lanes[name];
  lane.name = name;
  if (!lane.spans.empty() && std::isnan(lane.spans.back().t1_s)) {
    if (lane.spans.back().label == label) return;
    lane.spans.back().t1_s = t_s;
  }
  lane.spans.push_back({t_s, std::numeric_limits<double>::quiet_NaN(), std::move(label)});
}

void Leave(std::map<std::string, Lane>& lanes, const std::string& name, double t_s) {
  auto it = lanes.find(name);
  if (it == lanes.end() || it->second.spans.empty() || !std::isnan(it->second.spans.back().t1_s)) return;
  it->second.spans.back().t1_s = t_s;
}

std::vector<Series> Sorted(std::map<std::string, Series>& by_name) {
  std::vector<Series> out;
  out.reserve(by_name.size());
  for (auto& [name, s] : by_name) {
    std::stable_sort(s.points.begin(), s.points.end(),
                     [](const SeriesPoint& a, const SeriesPoint& b) { return a.t_s < b.t_s; });
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<Lane> Closed(std::map<std::string, Lane>& lanes, double t_end_s) {
  std::vector<Lane> out;
  for (auto& [name, lane] : lanes) {
    for (StateSpan& s : lane.spans) {
      if (std::isnan(s.t1_s)) s.t1_s = std::max(s.t0_s, t_end_s);
    }
    out.push_back(std::move(lane));
  }
  return out;
}

}  // namespace

void TrialSeriesBuilder::SeeTime(double t_s) { t_end_s_ = std::max(t_end_s_, t_s); }

void TrialSeriesBuilder::OnLogEvent(std::string_view component, const LogfmtFields& fields) {
  const auto event = FindField(fields, "event");
  const std::optional<double> t = Number(fields, "t");
  if (!event || !t) return;
  SeeTime(*t);
  const std::string node = FindField(fields, "node").value_or(std::string(component));
  const std::string& e = *event;
  if (e == "link") {
    OnLinkEvent(node, *t, fields);
  } else if (e == "leader_elected") {
    if (auto term = Number(fields, "term")) Add(term_, node, *t, *term);
    if (auto leader = FindField(fields, "leader")) Enter(leader_, node, *t, *leader);
  } else if (e == "raft_stopped" || e == "stopped") {
    Leave(leader_, node, *t);
    if (e == "stopped") Leave(stage_, node, *t);
  } else if (e == "battery") {
    if (auto f = Number(fields, "fraction")) Add(battery_, node, *t, *f);
  } else if (e == "mission_stage") {
    if (auto stage = FindField(fields, "stage")) Enter(stage_, node, *t, *stage);
  } else if (e == "flock_metrics") {
    for (const char* key : {"order", "safety", "union"}) {
      if (auto v = Number(fields, key)) Add(flock_, key, *t, *v);
    }
  }
}

void TrialSeriesBuilder::OnLinkEvent(const std::string& node, double t_s, const LogfmtFields& fields) {
  LinkBurst& burst = link_[node];
  if (burst.t_s != t_s) {
    FlushLink(node, burst);
    burst = LinkBurst{};
    burst.t_s = t_s;
  }
  const auto sent = Number(fields, "sent");
  const auto received = Number(fields, "received");
  if (sent && received) {
    burst.sent += *sent;
    burst.received += *received;
  } else if (auto loss = Number(fields, "loss")) {
    burst.loss_sum += *loss;
    burst.loss_n += 1;
  }
  const auto rtt = Number(fields, "rtt_ms_mean");
  if (rtt && received && *received > 0) {
    burst.rtt_sum += *rtt * *received;
    burst.rtt_w += *received;
  }
}

void TrialSeriesBuilder::FlushLink(const std::string& node, LinkBurst& burst) {
  if (burst.t_s < 0) return;
  if (burst.sent > 0) {
    Add(loss_, node, burst.t_s, 1.0 - burst.received / burst.sent);
  } else if (burst.loss_n > 0) {
    Add(loss_, node, burst.t_s, burst.loss_sum / burst.loss_n);
  }
  if (burst.rtt_w > 0) Add(rtt_, node, burst.t_s, burst.rtt_sum / burst.rtt_w);
  burst.t_s = -1;
}

void TrialSeriesBuilder::OnTruth(const TruthRow& row) {
  if (group_t_s_ && *group_t_s_ != row.t_s) FlushTruthGroup();
  group_t_s_ = row.t_s;
  SeeTime(row.t_s);
  if (truth_due_s_ && row.t_s < *truth_due_s_) return;  // between samples: not kept
  group_.push_back(row);
}

void TrialSeriesBuilder::FlushTruthGroup() {
  if (group_.empty()) return;
  const double t = group_.front().t_s;
  // The next sample at the next multiple of the period after this one.
  truth_due_s_ = (std::floor(t / truth_period_s_ + 1e-9) + 1) * truth_period_s_;
  for (std::size_t i = 0; i < group_.size(); ++i) {
    const TruthRow& r = group_[i];
    Add(altitude_, r.drone, t, r.z_m);
    if (r.has_velocity)
      Add(speed_, r.drone, t, std::sqrt(r.vx_m_s * r.vx_m_s + r.vy_m_s * r.vy_m_s + r.vz_m_s * r.vz_m_s));
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < group_.size(); ++j) {
      if (j == i || group_[j].drone == r.drone) continue;
      const double dx = r.x_m - group_[j].x_m, dy = r.y_m - group_[j].y_m, dz = r.z_m - group_[j].z_m;
      nearest = std::min(nearest, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
    if (std::isfinite(nearest)) Add(nearest_, r.drone, t, nearest);
  }
  group_.clear();
}

TrialSeries TrialSeriesBuilder::Finish() {
  FlushTruthGroup();
  group_t_s_.reset();
  for (auto& [node, burst] : link_) FlushLink(node, burst);
  TrialSeries s;
  s.t_end_s = t_end_s_;
  s.altitude_m = Sorted(altitude_);
  s.speed_m_s = Sorted(speed_);
  s.nearest_m = Sorted(nearest_);
  s.radio_loss = Sorted(loss_);
  s.radio_rtt_ms = Sorted(rtt_);
  s.raft_term = Sorted(term_);
  s.raft_leader = Closed(leader_, t_end_s_);
  s.battery = Sorted(battery_);
  s.mission_stage = Closed(stage_, t_end_s_);
  // order, safety, union in that order (as the event lists them), not by name.
  for (const char* key : {"order", "safety", "union"}) {
    auto it = flock_.find(key);
    if (it == flock_.end()) continue;
    std::stable_sort(it->second.points.begin(), it->second.points.end(),
                     [](const SeriesPoint& a, const SeriesPoint& b) { return a.t_s < b.t_s; });
    s.flock.push_back(std::move(it->second));
  }
  flock_.clear();
  return s;
}

}  // namespace swarmbox::report
