// swarmbox-bench flight: the flight stack's acceptance scenarios as figures, one logfmt line per
// scenario and seed (closed loop against the in-process physics library, seeded noise, the GPS
// correlated and delayed as a real receiver's), plus the cost of one control step. Seeds 1, 3, 7
// and 42 by default (the closed-loop tests' seeds), --seed N for one. Hover and steps run with the
// x500's standalone receiver and with an RTK-fixed one (field receiver=standalone|rtk; the RTK
// lines pass on absolute truth: truth_rms_m, target/truth_settle_s, truth_overshoot_pct). The
// scenarios take ~1 s of CPU each, so --quick keeps their full windows (the figures stay
// comparable) and only shortens the step-cost loop. Positions are in the receiver's frame unless
// named truth_ (see scenarios.hpp).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "bench.hpp"
#include "scenarios.hpp"
#include "sim_harness.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace {

using swarmbox::LogEvent;
namespace ft = swarmbox::flight::testing;

void Print(LogEvent& e) { std::printf("%s\n", e.str().c_str()); }

int Fail(const char* scenario, const swarmbox::Error& err) {
  LogEvent e(0.0, "bench", "scenario_failed");
  e.Add("suite", "flight").Add("scenario", scenario).Add("reason", err.ToString());
  Print(e);
  return 1;
}

int RunSeed(std::uint64_t seed) {
  const double window = 30.0;  // [s] of simulated hover measured
  int rc = 0;
  const auto seed_l = static_cast<long>(seed);
  // Hover and steps with each receiver: the x500's standalone one (x500.yaml) and an RTK-fixed
  // ZED-F9P (closed_loop_rtk_test.cpp). With RTK the targets are judged on absolute truth.
  for (const ft::Receiver rx : {ft::Receiver::kStandalone, ft::Receiver::kRtk}) {
    const bool rtk = rx == ft::Receiver::kRtk;
    if (auto m = ft::RunHover(seed, window, 0.0, 0.0, rx); m) {
      LogEvent e(0.0, "bench", "result");
      e.Add("suite", "flight").Add("scenario", "x500_hover").Add("receiver", ft::ReceiverName(rx))
          .Add("seed", seed_l).Add("window_s", window, 0)
          .Add("rms_m", m->rms_m).Add("max_m", m->max_m).Add("target_rms_m", m->target_rms_m)
          .Add("truth_rms_m", m->truth_rms_m).Add("gps_wander_rms_m", m->gps_wander_rms_m)
          .Add("est_rms_m", m->est_rms_m).Add("track_rms_m", m->track_rms_m).Add("issue_target_rms_m", 0.1)
          .Add("pass", (rtk ? m->truth_rms_m : m->rms_m) < 0.1);
      Print(e);
    } else {
      rc = Fail("x500_hover", m.error());
    }
    struct StepCase { const char* name; double dx, dy, dz; };
    for (const StepCase& c :
         {StepCase{"x500_step_10m", 10.0, 0.0, 0.0}, StepCase{"x500_climb_5m", 0.0, 0.0, 5.0}}) {
      if (auto m = ft::RunStep(seed, c.dx, c.dy, c.dz, rx); m) {
        LogEvent e(0.0, "bench", "result");
        const double settle = rtk ? std::max(m->settle_target_s, m->settle_truth_s) : m->settle_s;
        const double overshoot = rtk ? m->overshoot_truth_pct : m->overshoot_pct;
        e.Add("suite", "flight").Add("scenario", c.name).Add("receiver", ft::ReceiverName(rx))
            .Add("seed", seed_l).Add("settle_s", m->settle_s, 2).Add("settle_3d_s", m->settle_3d_s, 2)
            .Add("truth_settle_s", m->settle_truth_s, 2).Add("target_settle_s", m->settle_target_s, 2)
            .Add("overshoot_pct", m->overshoot_pct, 1).Add("truth_overshoot_pct", m->overshoot_truth_pct, 1)
            .Add("peak_speed_m_s", m->peak_speed_m_s, 2)
            .Add("pass", m->settled && settle < 6.0 && overshoot < 10.0);
        Print(e);
      } else {
        rc = Fail(c.name, m.error());
      }
    }
  }
  if (auto m = ft::RunHover(seed, window, 5.0, 1.5); m) {
    LogEvent e(0.0, "bench", "result");
    e.Add("suite", "flight").Add("scenario", "x500_wind_5mps").Add("receiver", "standalone")
        .Add("seed", seed_l).Add("gust_std_m_s", 1.5, 1)
        .Add("target_rms_m", m->target_rms_m).Add("max_m", m->max_m).Add("truth_rms_m", m->truth_rms_m)
        .Add("pass", m->target_rms_m < 0.5);
    Print(e);
  } else {
    rc = Fail("x500_wind_5mps", m.error());
  }
  if (auto m = ft::RunGpsDropout(seed, 5.0); m) {
    LogEvent e(0.0, "bench", "result");
    e.Add("suite", "flight").Add("scenario", "x500_gps_dropout_5s").Add("receiver", "standalone")
        .Add("seed", seed_l).Add("max_drift_m", m->max_drift_m)
        .Add("est_err_end_m", m->est_err_at_end_m).Add("max_err_after_m", m->max_err_after_m)
        .Add("final_err_m", m->final_err_m).Add("max_speed_after_m_s", m->max_speed_after_m_s, 2)
        .Add("crashed", m->crashed).Add("pass", !m->crashed && m->max_drift_m < 1.0 && m->final_err_m < 0.3);
    Print(e);
  } else {
    rc = Fail("x500_gps_dropout_5s", m.error());
  }
  for (const double loaded_kg : {0.0, 80.0}) {
    auto on = ft::RunHeavyTransfer(seed, 20.0, true, nullptr, loaded_kg);
    auto off = ft::RunHeavyTransfer(seed, 20.0, false, nullptr, loaded_kg);
    for (int k = 0; k < 2; ++k) {
      auto& m = k == 0 ? on : off;
      const char* name = loaded_kg > 0.0
                             ? (k == 0 ? "x8_transfer_20m_80kg_damping_on" : "x8_transfer_20m_80kg_damping_off")
                             : (k == 0 ? "x8_transfer_20m_damping_on" : "x8_transfer_20m_damping_off");
      if (!m) {
        rc = Fail(name, m.error());
        continue;
      }
      LogEvent e(0.0, "bench", "result");
      e.Add("suite", "flight").Add("scenario", name).Add("seed", seed_l).Add("arrival_s", m->arrival_s, 1)
          .Add("swing_at_arrival_deg", m->swing_at_arrival_deg, 2).Add("residual_swing_deg", m->residual_swing_deg, 2)
          .Add("max_swing_deg", m->max_swing_deg, 2).Add("final_err_m", m->final_err_m, 2);
      if (k == 0 && off) {
        e.Add("reduction_x", off->residual_swing_deg / std::max(1e-6, m->residual_swing_deg), 2)
            .Add("pass", m->residual_swing_deg < 10.0 && 2.0 * m->residual_swing_deg < off->residual_swing_deg);
      }
      Print(e);
    }
  }
  return rc;
}

int RunFlightBench(const swarmbox::bench::Args& args) {
  const long one_seed = args.GetInt("seed", -1);
  const std::uint64_t default_seeds[] = {1, 3, 7, 42};
  int rc = 0;
  const auto wall0 = std::chrono::steady_clock::now();
  if (one_seed >= 0) {
    rc = RunSeed(static_cast<std::uint64_t>(one_seed));
  } else {
    for (const std::uint64_t s : default_seeds) rc = std::max(rc, RunSeed(s));
  }
  const auto seed = static_cast<std::uint64_t>(one_seed >= 0 ? one_seed : 42);

  // Cost of one control step (estimator + cascade + mixer), hovering x500, and the whole
  // closed loop's speed against simulated time.
  {
    ft::RigOptions o;
    o.seed = seed;
    auto rig = ft::Rig::Create(o);
    if (!rig) return Fail("x500_step_cost", rig.error());
    ft::Rig& r = **rig;
    r.RunUntilMode(swarmbox::flight::FlightMode::kIdle, 3.0);
    (void)r.fc().Command(swarmbox::flight::Setpoint::Takeoff(5.0));
    r.RunUntilMode(swarmbox::flight::FlightMode::kHold, 20.0);
    const swarmbox::flight::SensorSample sample = ft::FromPhysics(r.world().sensors(r.drone()));
    const int n = args.quick ? 20000 : 200000;
    swarmbox::flight::SensorSample s = sample;
    const auto t0 = std::chrono::steady_clock::now();
    double sink = 0.0;
    for (int i = 0; i < n; ++i) {
      s.t_s += 0.004;
      sink += r.fc().Step(s).u[0];
    }
    const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() / n;
    LogEvent e(0.0, "bench", "result");
    e.Add("suite", "flight").Add("scenario", "x500_control_step").Add("steps", n).Add("ns_per_step", ns, 0)
        .Add("checksum", sink, 1);
    Print(e);
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  LogEvent e(0.0, "bench", "result");
  e.Add("suite", "flight").Add("scenario", "total").Add("wall_s", wall, 2).Add("quick", args.quick);
  Print(e);
  return rc;
}

}  // namespace

SWARMBOX_BENCH_SUITE(flight, "Flight stack closed loop: hover, steps, wind, GPS dropout, heavy-lift swing; step cost",
                     RunFlightBench);
