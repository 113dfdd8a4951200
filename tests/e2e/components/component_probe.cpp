// swarmbox_component_probe: the smallest user component, for the components e2e test. Writes a
// line to --out (its folder must exist and be writable), logs `event=probe_ready` (the trial's
// readiness pattern), waits for SIGTERM or SIGINT (the runner's stop), appends a line and exits 0.
// No clock, no network: what it shows is the container's life cycle and the collected file.
//
//   swarmbox_component_probe --out /tmp/probe/hello.txt
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>

int main(int argc, char** argv) {
  const char* out = nullptr;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--out") == 0) out = argv[i + 1];
  }
  if (out == nullptr) {
    std::fprintf(stderr, "usage: swarmbox_component_probe --out FILE\n");
    return 2;
  }
  sigset_t stop;
  sigemptyset(&stop);
  sigaddset(&stop, SIGTERM);
  sigaddset(&stop, SIGINT);
  sigprocmask(SIG_BLOCK, &stop, nullptr);  // delivered to sigwait below, never to a handler

  const char* trial = std::getenv("SWARMBOX_TRIAL");
  std::FILE* f = std::fopen(out, "w");
  if (f == nullptr) {
    std::fprintf(stderr, "swarmbox_component_probe: cannot write %s\n", out);
    return 1;
  }
  std::fprintf(f, "started trial=%s\n", trial != nullptr ? trial : "");
  std::fflush(f);
  std::printf("node=probe event=probe_ready out=%s\n", out);
  std::fflush(stdout);

  int signal = 0;
  sigwait(&stop, &signal);
  std::fprintf(f, "stopped signal=%d\n", signal);
  std::fclose(f);
  std::printf("node=probe event=probe_stopped signal=%d\n", signal);
  return 0;
}
