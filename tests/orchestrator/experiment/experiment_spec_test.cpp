// Experiment descriptions: parsing, factorial expansion, explicit codes, filters, derived seeds and
// the overrides each trial gets (pure), and PlanExperiment against the real trials/ folder.
#include "swarmbox/experiment/experiment_spec.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "swarmbox/experiment/experiment_runner.hpp"

namespace swarmbox::experiment {
namespace {

constexpr const char* kTwoByThree = R"(name: radio
base: ../smoke.yaml
set: {physics.rtf: 0}
factors:
  - name: loss
    key: network.mesh.loss
    levels: {a: 0, b: 0.05, c: 0.2}
  - name: size
    levels:
      a: {drones: [{name: scout_1, airframe: x500, pose: [0, 0, 0]}]}
      b: {drones: [{name: scout_1, airframe: x500, pose: [0, 0, 0]}, {name: scout_2, airframe: x500, pose: [4, 0, 0]}]}
    labels: {a: one, b: two}
repetitions: 2
seed: 1000
)";

ExperimentSpec Parse(const std::string& text) {
  auto doc = yaml::Parse(text, "exp.yaml");
  EXPECT_TRUE(doc) << doc.error().ToString();
  auto spec = ParseExperiment(*doc, "exp.yaml");
  EXPECT_TRUE(spec) << spec.error().ToString();
  return *spec;
}

std::string ParseError(const std::string& text) {
  auto doc = yaml::Parse(text, "exp.yaml");
  if (!doc) return doc.error().ToString();
  auto spec = ParseExperiment(*doc, "exp.yaml");
  if (spec) {
    auto trials = ExpandTrials(*spec);
    return trials ? std::string("no error") : trials.error().ToString();
  }
  return spec.error().ToString();
}

TEST(ExperimentSpec, FullFactorialInCodeOrderWithRepetitions) {
  ExperimentSpec spec = Parse(kTwoByThree);
  ASSERT_EQ(spec.factors.size(), 2u);
  auto trials = ExpandTrials(spec);
  ASSERT_TRUE(trials) << trials.error().ToString();
  ASSERT_EQ(trials->size(), 12u);  // 3 x 2 codes x 2 repetitions
  std::vector<std::string> ids;
  for (const PlannedTrial& t : *trials) ids.push_back(t.id);
  EXPECT_EQ(ids.front(), "radio-aa-r1");
  EXPECT_EQ(ids[1], "radio-aa-r2");
  EXPECT_EQ(ids[2], "radio-ab-r1");
  EXPECT_EQ(ids.back(), "radio-cb-r2");
  EXPECT_EQ(std::set<std::string>(ids.begin(), ids.end()).size(), ids.size());
}

TEST(ExperimentSpec, OverridesAreSetThenLevelsThenSeedAndName) {
  auto trials = ExpandTrials(Parse(kTwoByThree));
  ASSERT_TRUE(trials);
  const PlannedTrial& t = (*trials)[7];  // code bb, repetition 2
  EXPECT_EQ(t.code, "bb");
  EXPECT_EQ(t.repetition, 2);
  ASSERT_EQ(t.overrides.size(), 5u);
  EXPECT_EQ(t.overrides[0], "physics.rtf=0");
  EXPECT_EQ(t.overrides[1], "network.mesh.loss=0.05");
  EXPECT_EQ(t.overrides[2].rfind("drones=[{", 0), 0u) << t.overrides[2];
  EXPECT_EQ(t.overrides[3], "seed=" + std::to_string(t.seed));
  EXPECT_EQ(t.overrides[4], "name=radio-bb-r2");
  EXPECT_EQ(t.levels, (std::vector<std::string>{"0.05", "two"}));
}

TEST(ExperimentSpec, PairedSeedsRepeatAcrossCodesIndependentOnesDoNot) {
  ExperimentSpec spec = Parse(kTwoByThree);
  auto paired = ExpandTrials(spec);
  ASSERT_TRUE(paired);
  std::map<int, std::set<std::uint64_t>> by_rep;
  for (const PlannedTrial& t : *paired) by_rep[t.repetition].insert(t.seed);
  EXPECT_EQ(by_rep[1].size(), 1u);
  EXPECT_EQ(by_rep[2].size(), 1u);
  EXPECT_NE(*by_rep[1].begin(), *by_rep[2].begin());

  spec.seeds = SeedMode::kIndependent;
  auto independent = ExpandTrials(spec);
  ASSERT_TRUE(independent);
  std::set<std::uint64_t> seeds;
  for (const PlannedTrial& t : *independent) seeds.insert(t.seed);
  EXPECT_EQ(seeds.size(), independent->size());
  // Deterministic: the same inputs give the same seeds, below 2^31.
  EXPECT_EQ(DeriveSeed(1000, SeedMode::kIndependent, "ab", 2),
            DeriveSeed(1000, SeedMode::kIndependent, "ab", 2));
  for (std::uint64_t s : seeds) EXPECT_LT(s, 1ULL << 31U);
}

TEST(ExperimentSpec, ExplicitCodesAndFilter) {
  ExperimentSpec spec = Parse(std::string(kTwoByThree) + "codes: [cb, aa, ba]\nfilter: ['?a']\n");
  auto trials = ExpandTrials(spec);
  ASSERT_TRUE(trials) << trials.error().ToString();
  ASSERT_EQ(trials->size(), 4u);
  EXPECT_EQ((*trials)[0].id, "radio-aa-r1");
  EXPECT_EQ((*trials)[2].id, "radio-ba-r1");
  EXPECT_TRUE(CodeMatches("ab", "a?"));
  EXPECT_TRUE(CodeMatches("ab", "*b"));
  EXPECT_FALSE(CodeMatches("ab", "b?"));
  EXPECT_FALSE(CodeMatches("ab", "a"));
}

TEST(ExperimentSpec, ErrorsSayWhereAndWhat) {
  const std::string base = "name: x\nbase: t.yaml\nfactors:\n  - {name: f, key: seed, levels: {a: 1, b: 2}}\n";
  EXPECT_EQ(ParseError(base + "codes: [c]\n"),
            "exp.yaml:5:8: code 'c': factor f has no level 'c' (levels: ab)");
  EXPECT_EQ(ParseError(base + "codes: [ab]\n"),
            "exp.yaml:5:8: code 'ab' must have one letter per factor (1)");
  EXPECT_EQ(ParseError(base + "filter: [c]\n"), "exp.yaml: the filter leaves no trial to run");
  EXPECT_EQ(ParseError(base + "codes: [a, a]\n"), "exp.yaml: code 'a' is listed twice");
  EXPECT_EQ(ParseError(base + "repetitions: 0\n"), "exp.yaml:5:14: 'repetitions' must be at least 1");
  EXPECT_EQ(ParseError("name: x\nbase: t.yaml\nfactors:\n  - {name: f, levels: {A: {seed: 1}}}\n"),
            "exp.yaml:4:24: a level code is one letter a-z, got 'A'");
  EXPECT_EQ(ParseError("name: x\nbase: t.yaml\nfactors:\n  - {name: f, levels: {a: 3}}\n"),
            "exp.yaml:4:27: a level of a factor without 'key' must be a mapping of trial keys to "
            "values");
  EXPECT_NE(ParseError("name: x\nbase: t.yaml\nfactors: []\n").find("non-empty list"),
            std::string::npos);
  EXPECT_NE(ParseError(base + "colour: red\n").find("colour"), std::string::npos);
  EXPECT_NE(ParseError("name: a-very-long-experiment-name-indeed\nbase: t.yaml\nfactors:\n"
                       "  - {name: f, key: seed, levels: {a: 1}}\nrepetitions: 1000\n")
                .find("exceed 40 characters"),
            std::string::npos);
}

TEST(ExperimentSpec, AFactorWithSeveralKeysSetsThemAllPerLevel) {
  const ExperimentSpec spec = Parse(R"(name: swarm
base: t.yaml
factors:
  - name: scouts
    keys: [drones.scout.count, world_size_m]
    levels: {a: [5, [150, 150]], b: [100, [600, 600]]}
)");
  ASSERT_EQ(spec.factors.size(), 1u);
  EXPECT_EQ(spec.factors[0].keys, (std::vector<std::string>{"drones.scout.count", "world_size_m"}));
  auto trials = ExpandTrials(spec);
  ASSERT_TRUE(trials) << trials.error().ToString();
  ASSERT_EQ(trials->size(), 2u);
  EXPECT_EQ((*trials)[1].levels, std::vector<std::string>{"100"});  // labelled by the first value
  EXPECT_EQ((*trials)[1].overrides[0], "drones.scout.count=100");
  EXPECT_EQ((*trials)[1].overrides[1], "world_size_m=[600,600]");
}

TEST(ExperimentSpec, SeveralKeysErrorsSayWhereAndWhat) {
  EXPECT_EQ(ParseError("name: x\nbase: t.yaml\nfactors:\n  - {name: f, keys: [seed, name], levels: {a: [1]}}\n"),
            "exp.yaml:4:47: level 'a' must be a list of 2 values, one per key of 'keys' in that order");
  EXPECT_EQ(ParseError("name: x\nbase: t.yaml\nfactors:\n  - {name: f, keys: [seed], levels: {a: 1}}\n"),
            "exp.yaml:4:41: level 'a' must be a list of 1 values, one per key of 'keys' in that order");
  EXPECT_EQ(ParseError("name: x\nbase: t.yaml\nfactors:\n  - {name: f, key: seed, keys: [seed], levels: {a: [1]}}\n"),
            "exp.yaml:4:32: give 'key' (one trial key per level) or 'keys' (several), not both");
  EXPECT_EQ(ParseError("name: x\nbase: t.yaml\nfactors:\n  - {name: f, keys: [], levels: {a: [1]}}\n"),
            "exp.yaml:4:21: 'keys' must list at least one trial key");
}

// The shipped smoke trial as the base: every trial loads through the real loader, and a level
// value the trial schema refuses stops the plan with the trial's id.
class PlanExperimentTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(SWARMBOX_SOURCE_DIR) / "trials" / "experiments";
  }
  std::filesystem::path dir_;
};

TEST_F(PlanExperimentTest, LoadsEveryTrialWithItsOverrides) {
  auto doc = yaml::Parse(kTwoByThree, (dir_ / "exp.yaml").string());
  ASSERT_TRUE(doc);
  auto spec = ParseExperiment(*doc, (dir_ / "exp.yaml").string());
  ASSERT_TRUE(spec) << spec.error().ToString();
  spec->base_trial = (dir_ / ".." / "smoke.yaml").lexically_normal().string();
  auto plan = PlanExperiment(*spec);
  ASSERT_TRUE(plan) << plan.error().ToString();
  ASSERT_EQ(plan->specs.size(), 12u);
  const dsl::TrialSpec& t = plan->specs.at("radio-cb-r1");
  EXPECT_EQ(t.name, "radio-cb-r1");
  EXPECT_EQ(t.drones.size(), 2u);
  EXPECT_DOUBLE_EQ(t.rtf, 0);
  ASSERT_EQ(t.mesh.rules.size(), 1u);
  EXPECT_DOUBLE_EQ(t.mesh.rules[0].spec.loss, 0.2);
}

TEST_F(PlanExperimentTest, ABadLevelValueNamesTheTrial) {
  auto doc = yaml::Parse(
      "name: bad\nbase: ../smoke.yaml\nfactors:\n  - {name: rtf, key: physics.rtf, levels: {a: 0, b: fast}}\n",
      (dir_ / "bad.yaml").string());
  ASSERT_TRUE(doc);
  auto spec = ParseExperiment(*doc, (dir_ / "bad.yaml").string());
  ASSERT_TRUE(spec);
  spec->base_trial = (dir_ / ".." / "smoke.yaml").lexically_normal().string();
  auto plan = PlanExperiment(*spec);
  ASSERT_FALSE(plan);
  EXPECT_NE(plan.error().message().find("trial bad-b-r1 (code b)"), std::string::npos)
      << plan.error().ToString();
}

}  // namespace
}  // namespace swarmbox::experiment

namespace swarmbox::experiment {
namespace {

// Every experiment that ships in trials/experiments/ loads, expands and plans against the real
// trials folder (the README tutorial's experiment among them).
TEST(ShippedExperiments, LoadAndPlan) {
  const std::filesystem::path dir = std::filesystem::path(SWARMBOX_SOURCE_DIR) / "trials" / "experiments";
  int found = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() != ".yaml") continue;
    auto spec = LoadExperiment(e.path().string());
    ASSERT_TRUE(spec) << spec.error().ToString();
    ++found;
    auto plan = PlanExperiment(*spec);
    ASSERT_TRUE(plan) << e.path() << ": " << plan.error().ToString();
    EXPECT_EQ(plan->specs.size(), plan->trials.size());
  }
  EXPECT_GE(found, 2);
  auto radio = LoadExperiment((dir / "radio.yaml").string());
  ASSERT_TRUE(radio) << radio.error().ToString();
  auto trials = ExpandTrials(*radio);
  ASSERT_TRUE(trials);
  EXPECT_EQ(trials->size(), 81u);
  // The swarm-size experiment: 5 sizes of trials/swarm_100.yaml, each on its own area.
  auto swarm = LoadExperiment((dir / "swarm_size.yaml").string());
  ASSERT_TRUE(swarm) << swarm.error().ToString();
  auto swarm_plan = PlanExperiment(*swarm);
  ASSERT_TRUE(swarm_plan) << swarm_plan.error().ToString();
  const std::vector<std::pair<std::string, std::size_t>> sizes = {
      {"swarm_size-a-r1", 6}, {"swarm_size-b-r1", 11}, {"swarm_size-c-r1", 26}, {"swarm_size-d-r1", 51}, {"swarm_size-e-r1", 101}};
  for (const auto& [id, drones] : sizes) {
    ASSERT_EQ(swarm_plan->specs.count(id), 1u) << id;
    const dsl::TrialSpec& t = swarm_plan->specs.at(id);
    EXPECT_EQ(t.drones.size(), drones) << id;
    EXPECT_EQ(t.drones.back().name, "lifter") << id;
    EXPECT_TRUE(t.HasWorldSize()) << id;
  }
  EXPECT_EQ(swarm_plan->specs.at("swarm_size-a-r1").world_size_m, (std::array<double, 2>{150, 150}));
  EXPECT_EQ(swarm_plan->specs.at("swarm_size-e-r1").world_size_m, (std::array<double, 2>{600, 600}));
}

}  // namespace
}  // namespace swarmbox::experiment
