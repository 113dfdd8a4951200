#include "swarmbox/swarm/sighting_fusion.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {
namespace {

double Logit(double p) { return std::log(p / (1.0 - p)); }

struct Viewpoint {
  double x, y, h, t;
};

}  // namespace

std::string FusionParamsProblem(const FusionParams& p) {
  if (!(p.prior > 0 && p.prior < 1)) return "prior must be in (0, 1)";
  if (!(p.max_view_confidence > 0.5 && p.max_view_confidence < 1)) return "max_view_confidence must be in (0.5, 1)";
  if (!(p.min_baseline_m >= 0 && p.min_pass_interval_s >= 0)) return "min_baseline_m and min_pass_interval_s must be >= 0";
  if (!(p.detector_recall > 0 && p.detector_recall < 1)) return "detector_recall must be in (0, 1)";
  if (!(p.false_repeat >= 0 && p.false_repeat < p.detector_recall)) {
    return "false_repeat must be in [0, detector_recall): a miss must count against a candidate";
  }
  if (!(p.reject_belief > 0 && p.reject_belief < p.confirm_belief && p.confirm_belief < 1)) {
    return "expected 0 < reject_belief < confirm_belief < 1";
  }
  if (p.confirm_views < 2) return "confirm_views must be >= 2: a single view never confirms";
  if (!(p.miss_in_view_m > 0 && p.min_miss_height_m >= 0 && p.max_miss_height_m > p.min_miss_height_m)) {
    return "expected miss_in_view_m > 0 and 0 <= min_miss_height_m < max_miss_height_m";
  }
  if (p.close_look_height_m < 0) return "close_look_height_m must be >= 0 (0: no close looks)";
  if (p.close_look_height_m > 0) {
    if (!(p.max_search_log_odds >= 0)) return "max_search_log_odds must be >= 0";
    if (!(p.max_close_view_confidence > 0.5 && p.max_close_view_confidence < 1)) {
      return "max_close_view_confidence must be in (0.5, 1)";
    }
    if (!(p.close_recall > 0 && p.close_recall < 1 && p.close_false_repeat >= 0 &&
          p.close_false_repeat < p.close_recall)) {
      return "expected 0 <= close_false_repeat < close_recall < 1";
    }
  }
  if (p.max_revisits < 1) return "max_revisits must be >= 1";
  if (!(p.revisit_after_s >= 0 && p.revisit_timeout_s > 0)) return "expected revisit_after_s >= 0, revisit_timeout_s > 0";
  return "";
}

void CheckFusionParams(const FusionParams& p) {
  const std::string why = FusionParamsProblem(p);
  if (!why.empty()) {
    std::fprintf(stderr, "FusionParams: %s\n", why.c_str());
    std::abort();
  }
}

bool CloseLook(const raft::SightingView& view, const FusionParams& p) {
  return p.close_look_height_m > 0 && view.viewer_height_m <= p.close_look_height_m;
}

double ViewLogOdds(const raft::SightingView& view, const FusionParams& p) {
  const bool close = CloseLook(view, p);
  if (view.detected) {
    return Logit(
        std::clamp(view.confidence, 1e-6, close ? p.max_close_view_confidence : p.max_view_confidence));
  }
  if (close) return std::log((1.0 - p.close_recall) / (1.0 - p.close_false_repeat));
  return std::log((1.0 - p.detector_recall) / (1.0 - p.false_repeat));
}

bool MissInView(const raft::SightingView& view, double candidate_x_m, double candidate_y_m, const FusionParams& p) {
  const double off = std::hypot(view.viewer_x_m - candidate_x_m, view.viewer_y_m - candidate_y_m);
  return off <= p.miss_in_view_m && view.viewer_height_m >= p.min_miss_height_m &&
         view.viewer_height_m <= p.max_miss_height_m;
}

namespace {

// Whether view v is at least min_baseline_m (3-D) or min_pass_interval_s from every view counted.
bool Independent(const raft::SightingView& v, const std::vector<Viewpoint>& counted, const FusionParams& p) {
  for (const Viewpoint& q : counted) {
    const double baseline =
        std::sqrt((v.viewer_x_m - q.x) * (v.viewer_x_m - q.x) + (v.viewer_y_m - q.y) * (v.viewer_y_m - q.y) +
                  (v.viewer_height_m - q.h) * (v.viewer_height_m - q.h));
    if (baseline < p.min_baseline_m && std::abs(v.t_s - q.t) < p.min_pass_interval_s) return false;
  }
  return true;
}

// The decision on a candidate from its assessed evidence (the header's rules).
void Decide(const raft::Candidate& c, const FusionParams& p, FusionAssessment* a) {
  if (c.status == raft::CandidateStatus::kConfirmed) return;
  const bool looked = p.close_look_height_m <= 0 || a->close_detections >= 1;
  if (a->belief >= p.confirm_belief && a->counted_detections >= p.confirm_views && looked) {
    a->decision = FusionDecision::kConfirm;
  } else if (c.status == raft::CandidateStatus::kPending) {
    if (a->belief <= p.reject_belief && a->counted_misses >= 1) {
      a->decision = FusionDecision::kReject;
    } else if (static_cast<int>(c.revisits) >= p.max_revisits && c.revisit_drone.empty()) {
      a->decision = FusionDecision::kReject;
      a->undecided = true;
    }
  }
}

}  // namespace

FusionAssessment AssessCandidate(const raft::Candidate& c, const FusionParams& p) {
  FusionAssessment a;
  // The counted views' log-odds: from the search altitude (summed, then capped), close misses
  // (summed) and the best close detection (close looks of one object by one detector at one
  // scale are not independent either: the best counts, and outweighs the close misses).
  double search = 0, close_misses = 0, best_close = -1.0;
  std::vector<Viewpoint> counted;
  counted.reserve(c.views.size());
  for (const raft::SightingView& v : c.views) {
    a.last_view_s = std::max(a.last_view_s, v.t_s);
    if (v.detected) {
      ++a.detections;
    } else {
      ++a.misses;
      if (!MissInView(v, c.x_m, c.y_m, p)) continue;  // the place was not (well) in view: no evidence
    }
    if (!Independent(v, counted, p)) continue;
    counted.push_back({v.viewer_x_m, v.viewer_y_m, v.viewer_height_m, v.t_s});
    (v.detected ? a.counted_detections : a.counted_misses) += 1;
    if (!CloseLook(v, p)) {
      search += ViewLogOdds(v, p);
    } else if (v.detected) {
      ++a.close_detections;
      best_close = std::max(best_close, v.confidence);
    } else {
      close_misses += ViewLogOdds(v, p);
    }
  }
  double close = close_misses;
  if (p.close_look_height_m > 0) {
    search = std::min(search, p.max_search_log_odds);
    if (a.close_detections > 0) close = Logit(std::clamp(best_close, 1e-6, p.max_close_view_confidence));
  }
  a.log_odds = Logit(p.prior) + search + close;
  a.belief = 1.0 / (1.0 + std::exp(-a.log_odds));
  Decide(c, p, &a);
  return a;
}

void AddEvidence(LogEvent& e, const raft::Candidate& c, const FusionAssessment& a) {
  std::string drones, confidences, viewers, times;
  char buf[96];
  for (const raft::SightingView& v : c.views) {
    const char* sep = drones.empty() ? "" : ",";
    drones += sep + v.reporter;
    std::snprintf(buf, sizeof buf, "%s%.3f", sep, v.detected ? v.confidence : 0.0);
    confidences += buf;
    std::snprintf(buf, sizeof buf, "%s%.1f:%.1f:%.1f", sep, v.viewer_x_m, v.viewer_y_m, v.viewer_height_m);
    viewers += buf;
    std::snprintf(buf, sizeof buf, "%s%.2f", sep, v.t_s);
    times += buf;
  }
  e.Add("candidate", static_cast<std::int64_t>(c.id))
      .Add("x", c.x_m, 2)
      .Add("y", c.y_m, 2)
      .Add("belief", a.belief, 3)
      .Add("log_odds", a.log_odds, 2)
      .Add("views", a.detections)
      .Add("counted", a.counted_detections)
      .Add("misses", a.misses)
      .Add("counted_misses", a.counted_misses)
      .Add("close", a.close_detections)
      .Add("drones", drones)
      .Add("confidences", confidences)
      .Add("viewers", viewers)
      .Add("view_t", times);
}

}  // namespace swarmbox::swarm
