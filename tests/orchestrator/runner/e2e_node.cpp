// swarmbox-e2e-node: a tiny stand-in for swarmbox-physics / swarmbox-agent in the runner's
// end-to-end tests. Prints logfmt lines on a simulated clock; argv says what to do:
//   --name NAME          node name (default node)
//   --ready              print `event=ready` first
//   --tick-ms N          wall time per tick (default 20)
//   --step-s S           simulated seconds per tick (default 0.1)
//   --say T:TEXT         at simulated time T print `t=T node=NAME TEXT` (repeatable)
//   --exit T:CODE        at simulated time T print `crash` to stderr and exit with CODE
//   --truth PATH         write t_s,drone,x_m,y_m rows (a circle) every tick
//   --quiet-ticks        do not print a line per tick
// SIGTERM ends it with code 0 (it runs as PID 1 in its container).
#include <csignal>
#include <cstdio>
#include <cmath>
#include <cstdlib>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace {

volatile std::sig_atomic_t g_stop = 0;
extern "C" void OnTerm(int) { g_stop = 1; }

}  // namespace

int main(int argc, char** argv) {
  std::string name = "node";
  bool ready = false, quiet_ticks = false;
  long tick_ms = 20;
  double step_s = 0.1;
  std::vector<std::pair<double, std::string>> says;
  double exit_at = -1;
  int exit_code = 0;
  std::string truth;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (a == "--name") name = next();
    else if (a == "--ready") ready = true;
    else if (a == "--quiet-ticks") quiet_ticks = true;
    else if (a == "--tick-ms") tick_ms = std::atol(next().c_str());
    else if (a == "--step-s") step_s = std::atof(next().c_str());
    else if (a == "--truth") truth = next();
    else if (a == "--say" || a == "--exit") {
      const std::string v = next();
      const auto colon = v.find(':');
      if (colon == std::string::npos) {
        std::fprintf(stderr, "bad %s '%s' (expected T:VALUE)\n", a.c_str(), v.c_str());
        return 64;
      }
      const double t = std::atof(v.substr(0, colon).c_str());
      if (a == "--say") says.emplace_back(t, v.substr(colon + 1));
      else { exit_at = t; exit_code = std::atoi(v.substr(colon + 1).c_str()); }
    } else {
      std::fprintf(stderr, "unknown argument '%s'\n", a.c_str());
      return 64;
    }
  }
  std::signal(SIGTERM, OnTerm);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::FILE* csv = nullptr;
  if (!truth.empty()) {
    csv = std::fopen(truth.c_str(), "w");
    if (csv == nullptr) {
      std::perror(truth.c_str());
      return 65;
    }
    std::fprintf(csv, "t_s,drone,x_m,y_m,z_m\n");
  }
  if (ready) std::printf("t=0.000 node=%s event=ready\n", name.c_str());
  double t = 0;
  std::size_t said = 0;
  while (g_stop == 0) {
    while (said < says.size() && says[said].first <= t + 1e-9) {
      std::printf("t=%.3f node=%s %s\n", t, name.c_str(), says[said].second.c_str());
      ++said;
    }
    if (exit_at >= 0 && t + 1e-9 >= exit_at) {
      std::fprintf(stderr, "t=%.3f node=%s crash: exiting with code %d\n", t, name.c_str(), exit_code);
      if (csv != nullptr) std::fclose(csv);
      return exit_code;
    }
    if (!quiet_ticks) std::printf("t=%.3f node=%s event=tick\n", t, name.c_str());
    if (csv != nullptr) {
      std::fprintf(csv, "%.3f,%s,%.3f,%.3f,10.0\n", t, name.c_str(), 20 * std::cos(t / 5),
                   20 * std::sin(t / 5));
      std::fflush(csv);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(tick_ms));
    t += step_s;
  }
  if (csv != nullptr) std::fclose(csv);
  std::printf("t=%.3f node=%s event=stopped\n", t, name.c_str());
  return 0;
}
