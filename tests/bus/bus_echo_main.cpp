// swarmbox-bus-echo: the echo side of the two-process bus test (see bus_echo.hpp).
//   swarmbox-bus-echo --backend=fastdds --domain=140 --kind=lockstep --drone=drone_1
// Runs until SIGTERM/SIGINT. Exit 0 on a clean stop, 2 on bad arguments, 1 on a bus error.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <map>
#include <string>

#include "bus_echo.hpp"

namespace {
std::atomic<bool> g_stop{false};
extern "C" void OnSignal(int) { g_stop.store(true); }
}  // namespace

int main(int argc, char** argv) {
  std::map<std::string, std::string> options;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto eq = a.find('=');
    if (a.rfind("--", 0) != 0 || eq == std::string::npos) {
      std::fprintf(stderr, "swarmbox-bus-echo: expected --key=value, got '%s'\n", a.c_str());
      return 2;
    }
    options[a.substr(2, eq - 2)] = a.substr(eq + 1);
  }
  auto o = swarmbox::bus::testing::EchoOptionsFromMap(options);
  if (!o) {
    std::fprintf(stderr, "swarmbox-bus-echo: %s\n", o.error().ToString().c_str());
    return 2;
  }
  std::signal(SIGTERM, OnSignal);
  std::signal(SIGINT, OnSignal);
  auto s = swarmbox::bus::testing::RunEcho(*o, g_stop);
  if (!s) {
    std::fprintf(stderr, "swarmbox-bus-echo: %s\n", s.error().ToString().c_str());
    return 1;
  }
  return 0;
}
