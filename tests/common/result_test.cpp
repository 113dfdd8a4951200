#include "swarmbox/common/result.hpp"

#include <gtest/gtest.h>

#include <memory>

namespace swarmbox {
namespace {

Result<int> Half(int x) {
  if (x % 2 != 0) return Error(ErrorCode::kInvalidArgument, "odd number " + std::to_string(x), "half()");
  return x / 2;
}

Result<int> Quarter(int x) {
  auto h = Half(x);
  if (!h) return h.error().Context("quartering");
  return Half(*h);
}

Status CheckPositive(int x) {
  if (x <= 0) return Error(ErrorCode::kInvalidArgument, "not positive");
  return Ok{};
}

Status Chain(int x) {
  SWARMBOX_TRY(CheckPositive(x));
  SWARMBOX_TRY(Half(x));
  return Ok{};
}

TEST(Result, CarriesValueOrError) {
  auto q = Quarter(8);
  ASSERT_TRUE(q);
  EXPECT_EQ(*q, 2);
  auto bad = Quarter(6);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().ToString(), "half(): odd number 3");
  auto worse = Quarter(5);
  EXPECT_EQ(worse.error().ToString(), "half(): quartering: odd number 5");
  EXPECT_EQ(bad.value_or(-1), -1);
}

TEST(Result, MoveOnlyValues) {
  Result<std::unique_ptr<int>> r = std::make_unique<int>(7);
  ASSERT_TRUE(r);
  std::unique_ptr<int> p = std::move(r).value();
  EXPECT_EQ(*p, 7);
}

TEST(Result, TryPropagatesTheFirstError) {
  EXPECT_TRUE(Chain(4));
  EXPECT_EQ(Chain(-2).error().message(), "not positive");
  EXPECT_EQ(Chain(3).error().message(), "odd number 3");
}

TEST(Result, RetryableCodes) {
  EXPECT_TRUE(Error(ErrorCode::kUnavailable, "engine down").retryable());
  EXPECT_TRUE(Error(ErrorCode::kTimeout, "slow").retryable());
  EXPECT_FALSE(Error(ErrorCode::kInvalidArgument, "bad").retryable());
  EXPECT_EQ(ErrorCodeName(ErrorCode::kNotFound), "not_found");
}

TEST(ResultDeathTest, ValueOnErrorAborts) {
  Result<int> r = Error(ErrorCode::kInternal, "boom");
  EXPECT_DEATH((void)r.value(), "boom");
}

}  // namespace
}  // namespace swarmbox
