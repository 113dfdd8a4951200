// The README's brain ("Test your own swarm software") is real code: tests/docs/CMakeLists.txt cuts
// its ```cpp block out of README.md at configure time, builds it with swarmbox_add_brain as a user's
// build would, and this test loads it with the agent's loader and steps it: on the ground with the
// estimator ready it asks once for a take-off to the `height_m` of its arguments.
#include <gtest/gtest.h>

#include "swarmbox/brain/loader.hpp"

namespace swarmbox::brain {
namespace {

TEST(ReadmeBrain, LoadsAndAsksOnceForATakeOffToItsHeight) {
  Context ctx;
  ctx.self = "scout_1";
  ctx.members = {"scout_1"};
  ctx.args = {{"height_m", "12"}};
  auto loaded = LoadBrain(SWARMBOX_README_BRAIN, "climb", ctx);
  ASSERT_TRUE(loaded) << loaded.error().ToString();
  Brain& brain = **loaded;

  Input in;
  in.self.landed = true;
  in.self.flight_mode = "init";
  Output out;
  brain.Step(in, out);
  EXPECT_TRUE(out.commands.empty()) << "no take-off before the estimator is ready";
  EXPECT_EQ(out.status, "climb/init");

  in.t_ns = 4'000'000;
  in.self.flight_mode = "idle";
  out.Clear();
  brain.Step(in, out);
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(out.commands[0].kind, Command::Kind::kTakeoff);
  EXPECT_DOUBLE_EQ(out.commands[0].param, 12.0);
  EXPECT_EQ(out.status, "climb/idle");

  in.t_ns = 8'000'000;
  out.Clear();
  brain.Step(in, out);
  EXPECT_TRUE(out.commands.empty()) << "asked once";
}

}  // namespace
}  // namespace swarmbox::brain
