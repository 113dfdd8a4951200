// swarmbox-probe: a small C++ program of the tree that the end-to-end tests pack into a
// registry-free image (with its libstdc++/libc closure) and run in Docker.
//
//   swarmbox-probe serve N    "probe ready uid=U gid=G", then N "tick i" (stdout) and "warn i"
//                             (stderr) lines 10 ms apart; then waits for /tmp/stop to appear,
//                             prints "stopping: <its content>" and exits 3
//   swarmbox-probe exit K     prints "exec uid=U" and exits K
//   swarmbox-probe stream N   prints N lines "line i mono_ns=<CLOCK_MONOTONIC ns>" 10 ms apart
//   swarmbox-probe env NAME   prints "NAME=<value of the environment variable>" and exits 0
#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>

namespace {

int Serve(int n) {
  std::cout << "probe ready uid=" << getuid() << " gid=" << getgid() << std::endl;
  for (int i = 0; i < n; ++i) {
    std::cout << "tick " << i << std::endl;
    std::cerr << "warn " << i << std::endl;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  while (true) {
    std::ifstream stop("/tmp/stop");
    if (stop) {
      std::stringstream text;
      text << stop.rdbuf();
      std::string content = text.str();
      while (!content.empty() && content.back() == '\n') content.pop_back();
      std::cout << "stopping: " << content << std::endl;
      return 3;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

int Stream(int n) {
  for (int i = 0; i < n; ++i) {
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    const long long ns = static_cast<long long>(now.tv_sec) * 1000000000LL + now.tv_nsec;
    std::cout << "line " << i << " mono_ns=" << ns << std::endl;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "serve" && argc == 3) return Serve(std::atoi(argv[2]));
  if (mode == "exit" && argc == 3) {
    std::cout << "exec uid=" << getuid() << std::endl;
    return std::atoi(argv[2]);
  }
  if (mode == "stream" && argc == 3) return Stream(std::atoi(argv[2]));
  if (mode == "env" && argc == 3) {
    const char* value = std::getenv(argv[2]);
    std::cout << argv[2] << "=" << (value != nullptr ? value : "(unset)") << std::endl;
    return 0;
  }
  std::cerr << "usage: swarmbox-probe serve N | stream N | exit K | env NAME" << std::endl;
  return 2;
}
