// Flocking (see flocking.hpp): V18 terms plus Reynolds alignment/cohesion, no allocation per step.
#include "swarmbox/swarm/flocking.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {
namespace {

// The V18 friction rule for an imposed velocity v_other seen at clearance r: damp the part of the
// velocity difference that exceeds what can be braked within r - r0.
Vec2 FrictionRule(const Vec2& v_self, const Vec2& v_other, double r_m, double r0_m, double v_tol,
                  double a, double p, double gain) {
  const Vec2 dv = v_other - v_self;
  const double speed = dv.norm();
  const double v_allowed = std::max(v_tol, BrakingCurve(r_m - r0_m, a, p));
  if (speed <= v_allowed || speed < 1e-9) return Vec2::Zero();
  return gain * (speed - v_allowed) * dv / speed;
}

Vec2 ClampNorm(const Vec2& v, double max_norm) {
  const double n = v.norm();
  return n > max_norm ? Vec2(v * (max_norm / n)) : v;
}

// Clearance from p to the obstacle footprint (negative inside) and the unit normal pointing away
// from it at the nearest point.
double ObstacleClearance(const ObstacleFootprint& o, const Vec2& p, Vec2* away_normal) {
  const double c = std::cos(o.yaw_rad);
  const double s = std::sin(o.yaw_rad);
  const Vec2 d = p - o.center_m;
  const Vec2 q(c * d.x() + s * d.y(), -s * d.x() + c * d.y());  // in the obstacle's frame
  const Vec2 nearest(std::clamp(q.x(), -o.half_size_m.x(), o.half_size_m.x()),
                     std::clamp(q.y(), -o.half_size_m.y(), o.half_size_m.y()));
  Vec2 n_local;
  double clearance = 0.0;
  const double dist = (q - nearest).norm();
  if (dist > 1e-9) {
    n_local = (q - nearest) / dist;
    clearance = dist;
  } else {  // inside: leave through the nearest face
    const double fx = o.half_size_m.x() - std::abs(q.x());
    const double fy = o.half_size_m.y() - std::abs(q.y());
    if (fx < fy) {
      n_local = Vec2(q.x() >= 0 ? 1 : -1, 0);
      clearance = -fx;
    } else {
      n_local = Vec2(0, q.y() >= 0 ? 1 : -1);
      clearance = -fy;
    }
  }
  *away_normal = Vec2(c * n_local.x() - s * n_local.y(), s * n_local.x() + c * n_local.y());
  return clearance;
}

}  // namespace

double BrakingCurve(double r_m, double a_m_s2, double p_1_s) {
  if (r_m <= 0.0) return 0.0;
  const double linear = r_m * p_1_s;
  if (linear < a_m_s2 / p_1_s) return linear;
  return std::sqrt(2.0 * a_m_s2 * r_m - (a_m_s2 * a_m_s2) / (p_1_s * p_1_s));
}

double WallStandoffM(const FlockingParams& k) {
  const double a = k.a_shill_m_s2, p = k.p_shill_1_s, v = k.v_shill_m_s;
  // BrakingCurve inverted: linear up to a / p, then v^2 = 2 a r - a^2 / p^2.
  const double r = v <= a / p ? v / p : (v * v + a * a / (p * p)) / (2 * a);
  return k.r0_shill_m + r;
}

Flocking::Flocking(const FlockingParams& params, const Geofence& fence,
                   std::vector<ObstacleFootprint> obstacles)
    : params_(params), fence_(fence), obstacles_(std::move(obstacles)) {
  SWARMBOX_CHECK(params_.v_max_m_s > 0 && params_.a_max_m_s2 > 0 && params_.v_z_max_m_s > 0);
  SWARMBOX_CHECK(params_.stale_timeout_s > 0 && params_.fresh_age_s >= 0 &&
                 params_.fresh_age_s < params_.stale_timeout_s);
  SWARMBOX_CHECK(params_.p_mig_1_s > 0 && params_.p_frict_1_s > 0 && params_.p_shill_1_s > 0);
  SWARMBOX_CHECK(fence_.min_x_m < fence_.max_x_m && fence_.min_y_m < fence_.max_y_m);
  SWARMBOX_CHECK(params_.max_neighbours > 0);
  nearest_.reserve(static_cast<std::size_t>(params_.max_neighbours) + 1);
}

template <typename Fn>
void Flocking::ForEachWall(const Vec2& p, Fn&& fn) const {
  // Geofence walls: shill agents at the foot of the perpendicular, moving inward.
  fn(p.x() - fence_.min_x_m, Vec2(1, 0));
  fn(fence_.max_x_m - p.x(), Vec2(-1, 0));
  fn(p.y() - fence_.min_y_m, Vec2(0, 1));
  fn(fence_.max_y_m - p.y(), Vec2(0, -1));
  // Obstacles: a shill agent at the nearest point of the footprint, moving away from it.
  for (const ObstacleFootprint& o : obstacles_) {
    Vec2 n;
    const double clearance = ObstacleClearance(o, p, &n);
    fn(clearance, n);
  }
}

// The shill agents' push on a drone at rest (V18 eq. 5 with the drone's velocity taken as zero):
// inward within WallStandoffM, from the position alone. The part of V18's rule that depends on the
// drone's own velocity (braking it as it closes on a wall) is WallLimit below: fed back through
// the flight stack's lag at the 10 Hz mission tick with gain c_shill it swung the x500's attitude
// +-20-28 deg at ~1.4 Hz over the last 15 m of every lane toward a wall (2026-11-28,
// tests/agent/flight flocking_closed_loop_test.cpp).
Vec2 Flocking::ShillTerm(const Vec2& p) const {
  const FlockingParams& k = params_;
  Vec2 sum = Vec2::Zero();
  ForEachWall(p, [&](double clearance_m, const Vec2& away_normal) {
    sum += FrictionRule(Vec2::Zero(), k.v_shill_m_s * away_normal, clearance_m, k.r0_shill_m, 0.0,
                        k.a_shill_m_s2, k.p_shill_1_s, k.c_shill);
  });
  return sum;
}

// The commanded velocity's component toward each wall and obstacle face held to the speed that
// can still brake before the shill's stand-off (BrakingCurve(clearance - r0_shill, a_shill,
// p_shill); nothing toward it within r0_shill): a function of the position alone, so the braking
// follows the curve smoothly instead of through a velocity feedback loop. Only the normal
// component is cut: drones slide along walls.
Vec2 Flocking::WallLimit(const Vec2& p, Vec2 v) const {
  const FlockingParams& k = params_;
  ForEachWall(p, [&](double clearance_m, const Vec2& away_normal) {
    const double toward = -v.dot(away_normal);
    const double allowed = BrakingCurve(clearance_m - k.r0_shill_m, k.a_shill_m_s2, k.p_shill_1_s);
    if (toward > allowed) v += (toward - allowed) * away_normal;
  });
  return v;
}

FlockingOutput Flocking::Step(const FlockingInput& in, double dt_s) {
  SWARMBOX_CHECK(dt_s > 0);
  const FlockingParams& k = params_;
  FlockingOutput out;
  const Vec2 p = in.position_m.head<2>();
  const Vec2 v = in.velocity_m_s.head<2>();
  if (in.migrate) out.migration = MigrationTerm(in, p);
  ScanNeighbours(in, p, &out);
  FollowNeighbours(in, p, v, &out);
  // While migrating, cohesion weighs against the migration as it does at the cruise speed: scaled
  // by the migration's speed over v_flock. Unscaled, at its cap (v_coh_max, 2 m/s) it balanced the
  // braking migration 3.39 m short of the goal (BrakingCurve = 2 m/s there) and held a drone whose
  // neighbours were far off there for good (rubble20, 2026-11-28: a revisit 3.4 m off its
  // candidate for 40 s until it timed out, a returning scout 5 m off home).
  if (in.migrate) out.cohesion *= std::min(1.0, out.migration.norm() / k.v_flock_m_s);
  out.shill = ShillTerm(p);

  const Vec2 v_xy = WallLimit(
      p, ClampNorm(out.migration + out.repulsion + out.friction + out.alignment + out.cohesion + out.shill,
                   k.v_max_m_s));
  const double v_z =
      std::clamp(k.p_z_1_s * (in.goal_m.z() - in.position_m.z()), -k.v_z_max_m_s, k.v_z_max_m_s);
  Vec3 desired(v_xy.x(), v_xy.y(), v_z);

  const Vec3 previous = has_last_ ? last_command_m_s_ : in.velocity_m_s;
  Vec3 dv = desired - previous;
  const double dv_max = k.a_max_m_s2 * dt_s;
  if (dv.norm() > dv_max) dv *= dv_max / dv.norm();
  out.velocity_m_s = previous + dv;
  last_command_m_s_ = out.velocity_m_s;
  has_last_ = true;
  return out;
}

Vec2 Flocking::MigrationTerm(const FlockingInput& in, const Vec2& p) const {
  const FlockingParams& k = params_;
  Vec2 migration = Vec2::Zero();
  const Vec2 to_goal = in.goal_m.head<2>() - p;
  const double d = to_goal.norm();
  if (d > 1e-6) {
    const double speed = std::min(k.v_flock_m_s, BrakingCurve(d, k.a_mig_m_s2, k.p_mig_1_s));
    migration = speed * to_goal / d;
  }
  // Slide around obstacles: near one, the part of the migration that points into it turns
  // along its face (keeping the speed; head-on, toward the nearer end of the face, to the left
  // when in the middle), so that migration and the shill push do not cancel in front of a wall
  // (nor do two drones head-on either side of the middle slide into each other and stall).
  for (const ObstacleFootprint& o : obstacles_) {
    Vec2 n;
    const double clearance = ObstacleClearance(o, p, &n);
    const double into = -migration.dot(n);
    if (clearance > k.obstacle_slide_range_m || into <= 0.0) continue;
    const double speed = migration.norm();
    Vec2 along = migration + into * n;  // tangential part
    if (along.norm() < 0.05 * speed) {
      along = Vec2(-n.y(), n.x());
      if ((p - o.center_m).dot(along) < 0.0) along = -along;
    }
    migration = speed * along.normalized();
  }
  return migration;
}

void Flocking::ScanNeighbours(const FlockingInput& in, const Vec2& p, FlockingOutput* out) {
  const FlockingParams& k = params_;
  // The max_neighbours nearest in range and not stale (ties: the earlier in the input), kept
  // sorted by distance in a buffer of max_neighbours + 1; then used in input order, so that with
  // max_neighbours or fewer the sums are the same, term for term, as over every neighbour.
  const auto keep = static_cast<std::size_t>(k.max_neighbours);
  nearest_.clear();
  for (std::size_t i = 0; i < in.neighbours.size(); ++i) {
    const NeighbourState& n = in.neighbours[i];
    if (!(n.age_s <= k.stale_timeout_s)) continue;  // stale (or NaN age): dropped
    const double age = std::max(0.0, n.age_s);
    // Distances are 3-D (a drone far above or below is no threat), pushes horizontal.
    const Vec3 pj3 = n.position_m + age * n.velocity_m_s;
    const double r = (in.position_m - pj3).norm();
    if (r > k.sensing_range_m) continue;
    if (r < k.r0_rep_m) {  // repulsion: from every drone this close (safety first), not only the nearest 7
      Vec2 diff = p - pj3.head<2>();
      const double r_xy = diff.norm();
      if (r_xy < 1e-6) {  // stacked vertically: a deterministic direction per neighbour slot
        const double angle = 2.39996322972865332 * static_cast<double>(i + 1);  // golden angle
        diff = Vec2(std::cos(angle), std::sin(angle));
      } else {
        diff /= r_xy;
      }
      out->repulsion += k.p_rep_1_s * (k.r0_rep_m - r) * diff;
    }
    if (nearest_.size() == keep && !(r < nearest_.back().r_m)) continue;
    auto at = std::upper_bound(nearest_.begin(), nearest_.end(), r,
                               [](double value, const Near& e) { return value < e.r_m; });
    nearest_.insert(at, Near{r, i});
    if (nearest_.size() > keep) nearest_.pop_back();
  }
  std::sort(nearest_.begin(), nearest_.end(), [](const Near& a, const Near& b) { return a.index < b.index; });
}

void Flocking::FollowNeighbours(const FlockingInput& in, const Vec2& p, const Vec2& v,
                                FlockingOutput* out) const {
  const FlockingParams& k = params_;
  Vec2 centroid_sum = Vec2::Zero();
  Vec2 velocity_sum = Vec2::Zero();
  double weight_sum = 0.0;
  for (const Near& near : nearest_) {
    const NeighbourState& n = in.neighbours[near.index];
    const double age = std::max(0.0, n.age_s);
    const Vec2 pj = (n.position_m + age * n.velocity_m_s).head<2>();
    const Vec2 vj = n.velocity_m_s.head<2>();
    const double r = near.r_m;
    ++out->neighbours_used;
    const double w =
        age <= k.fresh_age_s ? 1.0 : (k.stale_timeout_s - age) / (k.stale_timeout_s - k.fresh_age_s);
    out->friction += w * FrictionRule(v, vj, r, k.r0_frict_m, k.v_frict_m_s, k.a_frict_m_s2,
                                      k.p_frict_1_s, k.c_frict);
    centroid_sum += w * pj;
    velocity_sum += w * vj;
    weight_sum += w;
  }
  if (weight_sum > 1e-9) {
    out->alignment = k.c_align * (velocity_sum / weight_sum - v);
    const Vec2 to_centroid = centroid_sum / weight_sum - p;
    const double d = to_centroid.norm();
    if (d > k.r0_coh_m) {
      out->cohesion = std::min(k.p_coh_1_s * (d - k.r0_coh_m), k.v_coh_max_m_s) * to_centroid / d;
    }
  }
}

}  // namespace swarmbox::swarm
