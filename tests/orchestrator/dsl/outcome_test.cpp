#include "swarmbox/dsl/outcome.hpp"

#include <gtest/gtest.h>

namespace swarmbox::dsl {
namespace {

TEST(Outcome, NamesRoundTrip) {
  for (Outcome o : {Outcome::kSuccess, Outcome::kTimeout, Outcome::kFailure, Outcome::kError}) {
    auto back = ParseOutcome(OutcomeName(o));
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(*back, o);
  }
  EXPECT_FALSE(ParseOutcome("crashed").has_value());
}

TEST(Outcome, OrderedFromBestToWorst) {
  EXPECT_LT(Outcome::kSuccess, Outcome::kTimeout);
  EXPECT_LT(Outcome::kTimeout, Outcome::kFailure);
  EXPECT_LT(Outcome::kFailure, Outcome::kError);
  EXPECT_EQ(Worse(Outcome::kFailure, Outcome::kTimeout), Outcome::kFailure);
}

struct MergeCase {
  Outcome first;
  Outcome second;
  Outcome merged;
  const char* reason;  // the reason that must survive
};

TEST(Verdict, KeepWorseKeepsTheMoreSevereAndTheFirstReasonOnTies) {
  const MergeCase cases[] = {
      {Outcome::kSuccess, Outcome::kFailure, Outcome::kFailure, "second"},
      {Outcome::kFailure, Outcome::kSuccess, Outcome::kFailure, "first"},
      {Outcome::kFailure, Outcome::kFailure, Outcome::kFailure, "first"},
      {Outcome::kTimeout, Outcome::kError, Outcome::kError, "second"},
      {Outcome::kError, Outcome::kTimeout, Outcome::kError, "first"},
  };
  for (const MergeCase& c : cases) {
    Verdict v = Verdict::Of(c.first, "first");
    v.KeepWorse(Verdict::Of(c.second, "second"));
    EXPECT_EQ(v.outcome, c.merged) << OutcomeName(c.first) << "+" << OutcomeName(c.second);
    EXPECT_EQ(v.reason, c.reason) << OutcomeName(c.first) << "+" << OutcomeName(c.second);
  }
}

TEST(Verdict, FromErrorIsAnInfrastructureErrorWithWhere) {
  Verdict v = Verdict::FromError(Error(ErrorCode::kUnavailable, "no engine", "/var/run/docker.sock"),
                                 "t/physics");
  EXPECT_EQ(v.outcome, Outcome::kError);
  EXPECT_EQ(v.reason, "/var/run/docker.sock: no engine");
  EXPECT_EQ(v.ToString(), "error: /var/run/docker.sock: no engine (t/physics)");
}

}  // namespace
}  // namespace swarmbox::dsl
