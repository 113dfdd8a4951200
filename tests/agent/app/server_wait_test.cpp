// ServerWait: the agent's wait for its first sensor sample, fed slices and sim/status messages by
// hand (no DDS, no clock).
#include "server_wait.hpp"

#include <gtest/gtest.h>

namespace swarmbox::agent {
namespace {

using std::chrono::milliseconds;

bus::Event Status(const std::string& name, int joined, int expected, const std::string& missing) {
  bus::Event e;
  e.node = "physics";
  e.name = name;
  e.fields = {
      {"joined", std::to_string(joined)}, {"expected", std::to_string(expected)}, {"missing", missing}};
  return e;
}

// Spends `ms` of wall time in 50 ms slices.
void Wait(ServerWait& w, int ms) {
  for (int spent = 0; spent < ms && !w.spent(); spent += 50) {
    const milliseconds slice = w.Slice(milliseconds(50));
    w.Spend(slice, slice);
  }
}

TEST(ServerWait, GivesUpAfterTheTimeoutWithNoSignOfTheServer) {
  ServerWait w(milliseconds(1000), "scout_16");
  Wait(w, 950);
  EXPECT_FALSE(w.spent());
  Wait(w, 50);
  EXPECT_TRUE(w.spent());
  EXPECT_EQ(w.Reason(), "within 1.0 s and no sign of the physics server (sim/status)");
}

// A 100-drone start: statuses a second apart keep the agent waiting far past its timeout.
TEST(ServerWait, WaitsAsLongAsTheServersStartProgresses) {
  ServerWait w(milliseconds(1000), "scout_16");
  for (int second = 0; second < 30; ++second) {
    Wait(w, 900);
    ASSERT_FALSE(w.spent()) << second;
    w.OnStatus(Status("joining", 40 + second, 101, "scout_16,scout_40"));
  }
  EXPECT_EQ(w.statuses(), 30);
  // The server then goes silent: the agent gives up one timeout after its last status.
  Wait(w, 1000);
  EXPECT_TRUE(w.spent());
  EXPECT_FALSE(w.left_out());
  EXPECT_EQ(w.Reason(),
            "for 1.0 s after the physics server's last status (joined 69/101, this drone missing)");
}

TEST(ServerWait, AStartThatEndsWithoutThisDroneEndsTheWait) {
  ServerWait w(milliseconds(10000), "scout_7");
  w.OnStatus(Status("joining", 3, 4, "scout_2"));
  EXPECT_FALSE(w.spent());
  w.OnStatus(Status("joined", 4, 4, ""));
  EXPECT_TRUE(w.spent());
  EXPECT_TRUE(w.left_out());
  EXPECT_EQ(w.Reason(), "and the physics server started without this drone (joined 4/4)");
}

// A drone lost at the start still gets samples (it may rejoin): the wait goes on.
TEST(ServerWait, ADroneLostAtTheStartKeepsWaiting) {
  ServerWait w(milliseconds(1000), "scout_1");
  w.OnStatus(Status("joined", 3, 4, "scout_10,scout_1"));
  EXPECT_FALSE(w.spent());
  EXPECT_FALSE(w.left_out());
}

}  // namespace
}  // namespace swarmbox::agent
