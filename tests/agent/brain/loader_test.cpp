// LoadBrain: libraries built in this tree by swarmbox_add_brain (tests/agent/brain/modules and the
// example rendezvous brain), each error the agent reports (exit 2) checked by its message.
//
// This program is linked with ENABLE_EXPORTS (-rdynamic) and registers a brain of its own, so its
// copy of swarmbox::brain's functions is in the global symbol scope: the worst case for a loaded
// library's SWARMBOX_BRAIN lines, which must still fill that library's own table.
#include "swarmbox/brain/loader.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace swarmbox::brain {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

class HostBrain final : public Brain {
 public:
  explicit HostBrain(const Context& /*ctx*/) {}
  void Step(const Input& /*in*/, Output& /*out*/) override {}
};

Context MakeContext(std::map<std::string, std::string> args = {}) {
  Context ctx;
  ctx.self = "scout_1";
  ctx.members = {"scout_2", "scout_1"};
  ctx.args = std::move(args);
  return ctx;
}

Output StepOnce(Brain& brain, std::int64_t t_ns = 4'000'000) {
  Vehicle self;
  self.name = "scout_1";
  self.flight_mode = "idle";
  Input in;
  in.t_ns = t_ns;
  in.self = self;
  Output out;
  brain.Step(in, out);
  return out;
}

std::string NamesOf(const std::vector<Registration>& table) {
  std::string names;
  for (const Registration& r : table) names += (names.empty() ? "" : ",") + std::string(r.name);
  return names;
}

TEST(BrainLoader, LoadsABrainAndStepsIt) {
  auto loaded = LoadBrain(SWARMBOX_TEST_BRAIN_A, "alpha", MakeContext({{"height_m", "12.5"}, {"label", "x"}}));
  ASSERT_TRUE(loaded) << loaded.error().ToString();
  EXPECT_EQ((*loaded)->name(), "alpha");
  EXPECT_EQ((*loaded)->path(), SWARMBOX_TEST_BRAIN_A);
  EXPECT_THAT((*loaded)->library_brains(), ElementsAre("alpha", "stateful", "thrower"));

  const Output out = StepOnce(**loaded, 8'000'000);
  EXPECT_EQ(out.status, "alpha/scout_1/x");
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(out.commands[0].kind, Command::Kind::kTakeoff);
  EXPECT_EQ(out.commands[0].param, 12.5);
  ASSERT_EQ(out.events.size(), 1u);
  EXPECT_EQ(out.events[0].fields[1].second, "8000000");
}

TEST(BrainLoader, EachLibraryFillsItsOwnTable) {
  // Given two libraries loaded at once next to this program's own registration ...
  auto a = LoadBrain(SWARMBOX_TEST_BRAIN_A, "alpha", MakeContext());
  auto b = LoadBrain(SWARMBOX_TEST_BRAIN_B, "beta", MakeContext());
  ASSERT_TRUE(a) << a.error().ToString();
  ASSERT_TRUE(b) << b.error().ToString();
  // ... each library's code sees its own table (not the program's, not the other library's) ...
  const Output out_a = StepOnce(**a);
  ASSERT_EQ(out_a.events.size(), 1u);
  EXPECT_EQ(out_a.events[0].fields[0].second, "alpha,stateful,thrower");
  EXPECT_EQ(StepOnce(**b).status, "beta/scout_1/beta");
  // ... the loader reads the same tables ...
  auto names_a = ListBrains(SWARMBOX_TEST_BRAIN_A);
  auto names_b = ListBrains(SWARMBOX_TEST_BRAIN_B);
  ASSERT_TRUE(names_a && names_b);
  EXPECT_THAT(*names_a, ElementsAre("alpha", "stateful", "thrower"));
  EXPECT_THAT(*names_b, ElementsAre("beta"));
  // ... and the program's table holds only its own brain.
  EXPECT_EQ(NamesOf(LibraryRegistry()), "host_brain");
}

TEST(BrainLoader, WrongAbiVersionNamesBothNumbers) {
  auto loaded = LoadBrain(SWARMBOX_TEST_BRAIN_WRONG_ABI, "alpha", MakeContext());
  ASSERT_FALSE(loaded);
  EXPECT_EQ(loaded.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(loaded.error().where(), SWARMBOX_TEST_BRAIN_WRONG_ABI);
  EXPECT_THAT(loaded.error().message(),
              HasSubstr("built against brain ABI " + std::to_string(kAbiVersion + 1) +
                        ", this agent speaks ABI " + std::to_string(kAbiVersion)));
}

TEST(BrainLoader, UnknownNameListsTheLibrarysBrains) {
  auto loaded = LoadBrain(SWARMBOX_TEST_BRAIN_A, "gamma", MakeContext());
  ASSERT_FALSE(loaded);
  EXPECT_EQ(loaded.error().message(),
            "no brain named \"gamma\" in the library; it has: alpha, stateful, thrower");
}

TEST(BrainLoader, ThrowingConstructorGivesItsMessage) {
  auto loaded = LoadBrain(SWARMBOX_TEST_BRAIN_A, "thrower", MakeContext({{"speed_m_s", "fast"}}));
  ASSERT_FALSE(loaded);
  EXPECT_EQ(loaded.error().message(),
            "brain \"thrower\": constructor failed: brain argument speed_m_s: expected a finite "
            "number, got \"fast\"");
}

TEST(BrainLoader, MissingFileGivesDlerror) {
  auto loaded = LoadBrain("/nonexistent/libnothing.so", "alpha", MakeContext());
  ASSERT_FALSE(loaded);
  EXPECT_EQ(loaded.error().where(), "/nonexistent/libnothing.so");
  EXPECT_THAT(loaded.error().message(), HasSubstr("cannot load the brain library: "));
  EXPECT_THAT(loaded.error().message(), HasSubstr("No such file or directory"));
}

TEST(BrainLoader, LibraryWithoutTheEntryPointsIsNoBrainLibrary) {
  auto loaded = LoadBrain(SWARMBOX_TEST_NOT_A_BRAIN, "alpha", MakeContext());
  ASSERT_FALSE(loaded);
  EXPECT_THAT(loaded.error().message(), HasSubstr("not a SwarmBox brain library"));
}

TEST(BrainLoader, UndefinedSymbolFailsAtLoadTime) {
  auto loaded = LoadBrain(SWARMBOX_TEST_BRAIN_UNDEFINED, "alpha", MakeContext());
  ASSERT_FALSE(loaded);
  EXPECT_THAT(loaded.error().message(), HasSubstr("cannot load the brain library: "));
  EXPECT_THAT(loaded.error().message(), HasSubstr("swarmbox_test_never_defined"));
}

TEST(BrainLoader, ReplicatedStateComesBackAsTheBrainsOwnAndOutlivesTheBrain) {
  auto loaded = LoadBrain(SWARMBOX_TEST_BRAIN_A, "stateful", MakeContext());
  ASSERT_TRUE(loaded) << loaded.error().ToString();
  std::unique_ptr<ReplicatedState> state = (*loaded)->MakeReplicatedState();
  ASSERT_NE(state, nullptr);
  const std::vector<std::uint8_t> entry = {1, 2, 3};
  state->Apply(1, entry);

  Input in;
  in.state = state.get();
  Output out;
  (*loaded)->Step(in, out);
  EXPECT_EQ(out.status, "own state, 3 bytes");

  // The brain goes first: the state's code is still loaded.
  loaded->reset();
  EXPECT_EQ(state->Snapshot(), std::vector<std::uint8_t>{3});
  const std::vector<std::uint8_t> snapshot = {9};
  EXPECT_TRUE(state->Restore(snapshot));
  EXPECT_EQ(state->Snapshot(), std::vector<std::uint8_t>{9});
}

TEST(BrainLoader, ExampleRendezvousBrainAsksForTakeoffFirst) {
  auto loaded = LoadBrain(SWARMBOX_EXAMPLE_RENDEZVOUS_BRAIN, "rendezvous",
                          MakeContext({{"altitude_m", "12"}}));
  ASSERT_TRUE(loaded) << loaded.error().ToString();
  const Output out = StepOnce(**loaded);
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(out.commands[0].kind, Command::Kind::kTakeoff);
  EXPECT_EQ(out.commands[0].param, 12.0);
  EXPECT_EQ(out.status, "rendezvous/takeoff");
}

TEST(BrainLoader, ExampleRendezvousBrainRefusesADroneOutsideTheMembers) {
  Context ctx = MakeContext();
  ctx.self = "lifter_1";
  auto loaded = LoadBrain(SWARMBOX_EXAMPLE_RENDEZVOUS_BRAIN, "rendezvous", ctx);
  ASSERT_FALSE(loaded);
  EXPECT_EQ(loaded.error().message(),
            "brain \"rendezvous\": constructor failed: drone \"lifter_1\" is not among the 2 members");
}

}  // namespace
}  // namespace swarmbox::brain

SWARMBOX_BRAIN("host_brain", swarmbox::brain::HostBrain)
