#include "swarmbox/docker/cancel_token.hpp"

#include <gtest/gtest.h>

namespace swarmbox::docker {
namespace {

TEST(CancelToken, WakesRegisteredWaitersOnceOnCancel) {
  CancelToken token;
  int woken = 0;
  const auto id = token.Register([&] { ++woken; });
  EXPECT_FALSE(token.cancelled());
  token.Cancel();
  token.Cancel();
  EXPECT_TRUE(token.cancelled());
  EXPECT_EQ(woken, 1);
  token.Unregister(id);
}

TEST(CancelToken, WakesAtOnceWhenRegisteredAfterCancel) {
  CancelToken token;
  token.Cancel();
  int woken = 0;
  token.Unregister(token.Register([&] { ++woken; }));
  EXPECT_EQ(woken, 1);
}

TEST(CancelToken, UnregisteredWakersAreNotCalled) {
  CancelToken token;
  int woken = 0;
  token.Unregister(token.Register([&] { ++woken; }));
  token.Cancel();
  EXPECT_EQ(woken, 0);
}

}  // namespace
}  // namespace swarmbox::docker
