// brain_loader_check LIBRARY NAME: loads brain NAME from LIBRARY with the installed loader, steps
// it once as a drone on the ground with a ready estimator, prints "<commands> <status>".
// Exit 1 with the loader's error.
#include <cstdio>

#include "swarmbox/brain/loader.hpp"

int main(int argc, char** argv) {
  namespace sb = swarmbox::brain;
  if (argc != 3) {
    std::fprintf(stderr, "usage: brain_loader_check LIBRARY NAME\n");
    return 2;
  }
  sb::Context ctx;
  ctx.self = "scout_1";
  ctx.members = {"scout_1", "scout_2"};
  auto brain = sb::LoadBrain(argv[1], argv[2], ctx);
  if (!brain) {
    std::fprintf(stderr, "%s\n", brain.error().ToString().c_str());
    return 1;
  }
  sb::Input in;
  in.t_ns = 4'000'000;
  in.self.name = "scout_1";
  in.self.flight_mode = "idle";
  sb::Output out;
  (*brain)->Step(in, out);
  for (const sb::Command& c : out.commands) std::printf("%s(%g) ", sb::CommandName(c.kind), c.param);
  std::printf("%s\n", out.status.c_str());
  return 0;
}
