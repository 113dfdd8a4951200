#include "kinematic_swarm.hpp"

#include <cmath>
#include <stdexcept>

namespace swarmbox::swarm::testing {

KinematicSwarm::KinematicSwarm(const KinematicSwarmConfig& config)
    : config_(config), rng_(config.seed), goal_m_(config.goal_m) {
  const auto n = static_cast<std::size_t>(config.agents);
  std::uniform_real_distribution<double> coord(-config.start_box_m / 2, config.start_box_m / 2);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int attempts = 0;
  while (pos_.size() < n) {
    if (++attempts > 100000) throw std::runtime_error("KinematicSwarm: start box too small");
    const Vec3 p(coord(rng_), coord(rng_), config.altitude_m);
    bool ok = true;
    for (const Vec3& q : pos_) ok = ok && (p - q).norm() >= config.min_start_spacing_m;
    if (!ok) continue;
    pos_.push_back(p);
    const double heading = 2 * M_PI * unit(rng_);
    const double speed = config.start_speed_max_m_s * unit(rng_);
    vel_.emplace_back(speed * std::cos(heading), speed * std::sin(heading), 0.0);
  }
  for (std::size_t i = 0; i < n; ++i) {
    flock_.emplace_back(config.params, config.fence, config.obstacles);
    flock_.back().Reset(vel_[i]);
    alive_.push_back(true);
    last_packet_.push_back({true, 0.0, pos_[i], vel_[i]});
    next_broadcast_s_.push_back(static_cast<double>(i) / static_cast<double>(n) / config.broadcast_hz);
  }
  scratch_.reserve(n);
}

void KinematicSwarm::Step() {
  const std::size_t n = pos_.size();
  const double dt = config_.dt_s;
  std::vector<Vec3> command(n, Vec3::Zero());
  for (std::size_t i = 0; i < n; ++i) {
    if (!alive_[i]) continue;
    scratch_.clear();
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i || !last_packet_[j].valid) continue;
      scratch_.push_back({last_packet_[j].pos, last_packet_[j].vel, t_s_ - last_packet_[j].t_s});
    }
    command[i] = flock_[i].Step({pos_[i], vel_[i], goal_m_, scratch_}, dt).velocity_m_s;
  }
  const double alpha = 1.0 - std::exp(-dt / config_.tau_s);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  t_s_ += dt;
  for (std::size_t i = 0; i < n; ++i) {
    if (!alive_[i]) continue;
    vel_[i] += alpha * (command[i] - vel_[i]);
    pos_[i] += dt * vel_[i];
    if (t_s_ >= next_broadcast_s_[i]) {
      next_broadcast_s_[i] += 1.0 / config_.broadcast_hz;
      if (unit(rng_) >= config_.loss) last_packet_[i] = {true, t_s_, pos_[i], vel_[i]};
    }
  }
}

void KinematicSwarm::Remove(int agent) { alive_[static_cast<std::size_t>(agent)] = false; }

int KinematicSwarm::alive_count() const {
  int c = 0;
  for (bool a : alive_) c += a ? 1 : 0;
  return c;
}

std::vector<Vec3> KinematicSwarm::AlivePositions() const {
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < pos_.size(); ++i)
    if (alive_[i]) out.push_back(pos_[i]);
  return out;
}

std::vector<Vec3> KinematicSwarm::AliveVelocities() const {
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < vel_.size(); ++i)
    if (alive_[i]) out.push_back(vel_[i]);
  return out;
}

FlockMetrics KinematicSwarm::Metrics(const FlockMetricsParams& params) const {
  const std::vector<Vec3> p = AlivePositions();
  const std::vector<Vec3> v = AliveVelocities();
  return ComputeFlockMetrics(p, v, params);
}

}  // namespace swarmbox::swarm::testing
