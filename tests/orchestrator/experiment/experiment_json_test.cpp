// experiment.json: what the experiment is and what produced it (issue #16: provenance), written
// with the fake engine's GET /version.
#include <gtest/gtest.h>

#include "support/fake_docker_api.hpp"
#include "swarmbox/common/version.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/experiment/experiment_runner.hpp"

namespace swarmbox::experiment {
namespace {

TEST(ExperimentJson, NamesTheExperimentAndCarriesItsProvenancePerHost) {
  ExperimentPlan plan;
  plan.spec.name = "radio";
  plan.spec.file = "trials/experiments/radio.yaml";
  plan.spec.base_trial = "trials/sar_search.yaml";
  Factor loss;
  loss.name = "loss";
  plan.spec.factors = {loss};
  plan.trials.resize(2);
  plan.specs["radio-a-r1"] = dsl::TrialSpec::Named("radio-a-r1").Rtf(0);
  plan.specs["radio-b-r1"] = dsl::TrialSpec::Named("radio-b-r1").Rtf(0);
  testing::FakeDockerApi api;
  PoolHost local{"local", 2, &api, nullptr, {"swarmbox/physics:bb22", "swarmbox/agent:aa11"}, "swarmbox/faults:cc33"};

  auto doc = yaml::Parse(ExperimentJson(plan, {"20261121-195623-5238"}, {local}), "experiment.json");
  ASSERT_TRUE(doc) << doc.error().ToString();
  EXPECT_EQ(doc->Find("name")->scalar(), "radio");
  EXPECT_EQ(doc->Find("trials")->scalar(), "2");
  const yaml::Node* p = doc->Find("provenance");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->Find("swarmbox_version")->scalar(), std::string(Build().version));
  EXPECT_EQ(p->Find("swarmbox_commit")->scalar(), std::string(Build().commit));
  EXPECT_EQ(p->Find("build_type")->scalar(), std::string(Build().build_type));
  EXPECT_FALSE(p->Find("host_name")->scalar().empty());
  EXPECT_EQ(p->Find("rtf_requested")->scalar(), "0");
  const yaml::Node* hosts = p->Find("hosts");
  ASSERT_TRUE(hosts != nullptr && hosts->items().size() == 1u);
  const yaml::Node& h = hosts->items()[0];
  EXPECT_EQ(h.Find("name")->scalar(), "local");
  EXPECT_EQ(h.Find("docker_version")->scalar(), "20.10.24+dfsg1");
  EXPECT_EQ(h.Find("docker_api_version")->scalar(), "1.41");
  EXPECT_EQ(h.Find("kernel")->scalar(), "6.1.0-fake-amd64");
  ASSERT_EQ(h.Find("images")->items().size(), 3u);
  EXPECT_EQ(h.Find("images")->items()[0].scalar(), "swarmbox/agent:aa11");
  EXPECT_EQ(h.Find("images")->items()[2].scalar(), "swarmbox/faults:cc33");

  EXPECT_TRUE(p->Find("fault_mechanisms")->items().empty());  // before any trial ran
  EXPECT_TRUE(p->Find("rtf_achieved_min")->is_null());

  // At the end: what the trials' result.json said.
  report::Provenance t1, t2, t3;
  t1.fault_mechanism = "netem";
  t1.rtf_achieved = 3.5;
  t2.fault_mechanism = "none";
  t2.rtf_achieved = 2.25;
  t3.fault_mechanism = "netem";
  auto after = yaml::Parse(ExperimentJson(plan, {"20261121-195623-5238"}, {local}, {t1, t2, t3}), "experiment.json");
  ASSERT_TRUE(after);
  const yaml::Node* ap = after->Find("provenance");
  ASSERT_EQ(ap->Find("fault_mechanisms")->items().size(), 2u);
  EXPECT_EQ(ap->Find("fault_mechanisms")->items()[0].scalar(), "netem");
  EXPECT_EQ(ap->Find("fault_mechanisms")->items()[1].scalar(), "none");
  EXPECT_EQ(ap->Find("rtf_achieved_min")->scalar(), "2.25");
  EXPECT_EQ(ap->Find("rtf_achieved_max")->scalar(), "3.5");

  // Trials that differ in their pace: no one rtf for the experiment (each result.json has its own).
  plan.specs["radio-b-r1"].rtf = 1;
  auto mixed = yaml::Parse(ExperimentJson(plan, {}, {local}), "experiment.json");
  ASSERT_TRUE(mixed);
  EXPECT_TRUE(mixed->Find("provenance")->Find("rtf_requested")->is_null());
}

}  // namespace
}  // namespace swarmbox::experiment
