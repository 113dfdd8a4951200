// SightingFusion: how much the swarm believes that a candidate (a place where some detector fired,
// raft::Candidate) is a person, from every view of it, and what to do about it. Pure: the committed
// evidence in, a belief and a decision out; the leader runs it (leader_planner.hpp) and proposes
// the decision (raft ConfirmSighting / RejectSighting / RequestRevisit), so every drone and every
// later leader sees the same outcome.
//
// The rule (log-odds fusion of independent views, e.g. Thrun, Burgard, Fox, "Probabilistic
// Robotics" §4.2 binary Bayes filter):
//   L = logit(prior) + sum over counted views of l(view)
//   detection with confidence c:  l = logit(min(c, max_view_confidence)) - logit(0.5)
//       (the detector's confidence read as its posterior at even odds, as a classifier trained
//        on balanced person/background samples reports it; capped so that no single frame is
//        near-certain)
//   miss (the place in view, nothing detected): l = ln((1 - detector_recall) / (1 - false_repeat))
//       P(nothing | a person there) = 1 - recall; P(nothing | a false alarm) = 1 - the chance
//       that what fired once fires again from another view.
//   belief = 1 / (1 + exp(-L)).
// Independence: frames taken close together from nearly the same pose are nearly the same image
// and their errors are correlated, so a view counts only when it is at least min_baseline_m (3-D)
// from every view counted so far, or at least min_pass_interval_s after it (another pass: the spot
// left the footprint in between). Views that do not count are kept in the record but add nothing.
// A miss counts only if the place was in view at adequate altitude: the viewer within
// miss_in_view_m horizontally of the candidate and between min/max_miss_height_m above ground.
//
// Close looks (close_look_height_m > 0: the mission's revisits descend to look from 18 m,
// ScoutConfig::revisit_look_altitude_m, where the detector's precision is higher than at the 30 m
// search altitude and the object is seen at another scale, against other pixels around it):
// a view from at most close_look_height_m above ground is a close look, with its own cap
// (max_close_view_confidence) and miss model (close_recall, close_false_repeat); the search
// altitude's views together add at most max_search_log_odds (they are many views of one object
// from nearly the same height and scale, and a look-alike fires on each: rubble20 on 2026-11-28
// confirmed 31 false victims so); of the close looks, the best detection counts alone (several
// weak close looks at a look-alike are no stronger than one), the close misses add up when no
// close look detected anything; and only a close look can confirm:
//   L = logit(prior) + min(sum of search views, max_search_log_odds)
//       + (logit(best close detection) or, without one, the sum of the close misses).
//
// Decisions (Decide):
//   kConfirm  belief >= confirm_belief AND at least confirm_views counted detections (with close
//             looks: at least one of them a close look): a single view never confirms, however
//             confident;
//   kReject   pending, belief <= reject_belief and at least one counted miss; or pending with
//             max_revisits revisits done and still undecided (logged as reason=undecided);
//   kNone     otherwise (the leader sends a revisit when no new view came for revisit_after_s).
//
//   const FusionAssessment a = AssessCandidate(candidate, params);
//   if (a.decision == FusionDecision::kConfirm) propose ConfirmSighting{candidate.id, a.belief};
#pragma once

#include <cstdint>
#include <string>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/raft/mission_state.hpp"

namespace swarmbox::swarm {

// Defaults: the reasons are in the comments; every one is a MissionTuning field (sar_brain.hpp).
struct FusionParams {
  // Prior that a first detection at a new place is a person, before its confidence counts. 0.5:
  // no measured base rate yet (the detector branch's precision at 30 m would be one); with it,
  // one view's belief equals its (capped) confidence.
  double prior = 0.5;
  // No single frame counts for more than 19:1 (0.95): HERIDAL's best published precision is 0.90
  // (issue #19), so a frame-level confidence above that is not calibrated.
  double max_view_confidence = 0.95;
  // Two frames >= 10 m apart at the 30 m search altitude look at the spot from directions >= 18
  // degrees apart, against other background pixels and at another place in the image [m].
  double min_baseline_m = 10.0;
  // At 7 m/s a spot crosses the 31 m along-track footprint (x500 camera at 30 m) in ~4.4 s: a view
  // 10 s later is from another pass or a revisit [s].
  double min_pass_interval_s = 10.0;
  // Detector recall where a revisit looks from (issue #19's target at 30 m, people half visible).
  // Measured on the mission's own frames (`swarmbox-bench perception --replay RUN`: frames with a
  // person within miss_in_view_m of the nadir at 10-40 m), sar_rubble seeds 42, 7, 8, 9: 0.74 (58
  // of 78 views) with the first detector of 2026-11-28, 0.83 (65 of 78) with the wider CNN shipped
  // after it and again with its hard-negative retraining; 0.85 stays until more runs measure it.
  double detector_recall = 0.85;
  // Chance that a false alarm fires again from another view. The same replay measures 0.03 per
  // frame over the places where one fired (7 of 226 frames; 0.10, 18 of 188, with the wider CNN:
  // debris; 0.06, 6 of 98, with its hard-negative retraining), but the places that do fire again
  // fire on every pass (backpacks: every false victim of rubble20 on 2026-11-28), so the
  // assumption stays above the average: 0.3.
  double false_repeat = 0.3;
  double confirm_belief = 0.95;  // confirm at >= 19:1 ...
  int confirm_views = 2;         // ... and with at least this many counted detections
  // Reject at <= 1:4: e.g. one 0.9 view then two counted misses (belief 0.29 -> 0.08).
  double reject_belief = 0.2;
  // A miss counts with the candidate within 5 m of the camera's nadir (well inside the 31 x 41 m
  // footprint at 30 m) ...
  double miss_in_view_m = 5.0;
  // ... from 10-40 m above ground: 40 m keeps a lying person >= 10 px on the x500's 320 px,
  // 1.2 rad camera; below 10 m the footprint is smaller than the geolocation spread [m].
  double min_miss_height_m = 10.0;
  double max_miss_height_m = 40.0;
  // Close looks (above); 0: off, every view alike (the fusion before 2026-11-28's close look).
  double close_look_height_m = 0;
  // logit(0.9): the search views raise a candidate to 9:1 at most; one close look at >= 0.68
  // confirms it; a close look that sees nothing leaves 0.49 (2.20 - 2.25), a second rejects it.
  // Measured on rubble20 (2026-11-28, BENCHMARKS.md "Perception: the close look"): with logit(0.8)
  // (a close look >= 0.83 confirms) 54 of 80 people were rescued and 9 false victims; the people
  // rejected had close looks at 0.6-0.8, and on that run's decisions a close look >= 0.70 would
  // have confirmed 47 of 51 real candidates and 11 of 75 false ones against 39 and 5. With
  // logit(0.9): 64 rescued, 26 false victims: a trade either way (the detector sets the limit).
  double max_search_log_odds = 2.197;
  double max_close_view_confidence = 0.99;
  // The detector's recall from the look altitude, per look (a look is 2 s, ~4 frames), and its
  // chance to fire on what the search model fired on. Measured per look on the mission's own
  // decided candidates (`swarmbox-bench perception --looks RUN`, rubble20 with the shipped 48 px
  // model; BENCHMARKS.md "The sweep's lane ends, rejoined lanes and the close looks per look"):
  // 0.83 (84 of 101 looks at people) and 0.35-0.42 over three runs (82 of 197 on the first, most
  // at 0.5-0.7). The assumptions stay 0.9 and 0.05: a close miss weighs only while no close look
  // detected anything (the best detection counts alone), and deciding that run's candidates again
  // with the measured pair (`--looks RUN --fusion-close-recall 0.83 --fusion-close-false-repeat
  // 0.41`: a miss -1.24 instead of -2.25) leaves 65 of 93 rejected false candidates and 3 of 12
  // rejected people open for another look, ~9 more false victims for ~2 more people at those
  // rates. The limit is the detector's close look (people and look-alikes overlap at 0.5-0.8).
  double close_recall = 0.9;
  double close_false_repeat = 0.05;
  int max_revisits = 3;             // then an undecided candidate is rejected (reason=undecided)
  double revisit_after_s = 10.0;    // no new view this long after the last: send a revisit [s]
  double revisit_timeout_s = 60.0;  // a revisit not done by then goes to another drone [s]
};

enum class FusionDecision { kNone, kConfirm, kReject };

struct FusionAssessment {
  double log_odds = 0.0;
  double belief = 0.5;            // [0, 1]
  int detections = 0;             // detections in the record
  int counted_detections = 0;     // ... that counted (independent)
  int misses = 0;                 // misses in the record
  int counted_misses = 0;         // ... that counted (in view, independent)
  int close_detections = 0;       // counted detections that were close looks
  double last_view_s = 0.0;       // capture time of the latest evidence [s]
  FusionDecision decision = FusionDecision::kNone;
  bool undecided = false;         // kReject because max_revisits ran out
};

// What is wrong with the parameters ("" when nothing): for the start-up check of the agent's args.
std::string FusionParamsProblem(const FusionParams& p);
// Aborts when FusionParamsProblem is not empty (a broken invariant past start-up).
void CheckFusionParams(const FusionParams& p);

// The log-odds contribution of one piece of evidence (before the independence rule and the cap on
// the search altitude's views).
double ViewLogOdds(const raft::SightingView& view, const FusionParams& p);
// Whether a view is a close look (close_look_height_m > 0 and the viewer at most that high).
bool CloseLook(const raft::SightingView& view, const FusionParams& p);
// Whether a miss had the candidate's place in view at adequate altitude.
bool MissInView(const raft::SightingView& view, double candidate_x_m, double candidate_y_m, const FusionParams& p);

FusionAssessment AssessCandidate(const raft::Candidate& candidate, const FusionParams& p);

// The evidence as logfmt fields: candidate, x, y, belief, views, counted, misses, and per view
// (in record order, comma separated) drones, confidences (0 for a miss), viewers "x:y:h", t.
void AddEvidence(LogEvent& e, const raft::Candidate& candidate, const FusionAssessment& a);

}  // namespace swarmbox::swarm
