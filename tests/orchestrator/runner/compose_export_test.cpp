#include "swarmbox/runner/compose_export.hpp"

#include <gtest/gtest.h>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/dsl/trial_loader.hpp"
#include "swarmbox/runner/plan.hpp"

namespace swarmbox::runner {
namespace {

TEST(ComposeYaml, ExportsNetworksServicesAndStartOrder) {
  dsl::LoadOptions load;
  load.overrides = {"radio.model=netem"};  // both networks (ChannelExportHasNoMeshNetwork: the channel's)
  auto spec = dsl::LoadTrial(std::string(SWARMBOX_SOURCE_DIR) + "/trials/sar_search.yaml", load);
  ASSERT_TRUE(spec) << spec.error().ToString();
  PlanOptions o;
  o.run_id = "compose";
  o.images = {"swarmbox/physics:abc", "swarmbox/agent:def"};
  o.subnets = {*Ipv4Net::Parse("10.200.8.0/24"), *Ipv4Net::Parse("10.200.9.0/24")};
  o.trials_dir = "/src/trials";
  auto trial = PlanTrial(*spec, o);
  ASSERT_TRUE(trial);
  ComposeOptions co;
  co.host_prefix = "/src/trials";
  co.relative_prefix = "../trials";
  co.header_comment = "exported by swarmbox compose\n\nline three";
  const std::string text = ComposeYaml(**trial, co);
  EXPECT_EQ(text.rfind("# exported by swarmbox compose\n#\n# line three\n", 0), 0u) << text;

  auto doc = yaml::Parse(text, "compose.yaml");
  ASSERT_TRUE(doc) << doc.error().ToString() << "\n" << text;
  EXPECT_EQ(doc->Find("version")->scalar(), "2.4");
  const yaml::Node* sim = doc->Find("networks")->Find("sim");
  ASSERT_NE(sim, nullptr);
  EXPECT_EQ(sim->Find("name")->scalar(), "sar-search-compose-net1-sim");
  EXPECT_EQ(sim->Find("ipam")->Find("config")->items()[0].Find("subnet")->scalar(), "10.200.8.0/24");
  EXPECT_EQ(sim->Find("labels")->Find("swarmbox.run")->scalar(), "compose");

  const yaml::Node* services = doc->Find("services");
  ASSERT_EQ(services->entries().size(), 5u);
  const yaml::Node* physics = services->Find("physics");
  EXPECT_EQ(physics->Find("image")->scalar(), "swarmbox/physics:abc");
  EXPECT_EQ(physics->Find("entrypoint")->items()[0].scalar(), "/usr/local/bin/swarmbox-physics");
  EXPECT_EQ(physics->Find("networks")->Find("sim")->Find("ipv4_address")->scalar(), "10.200.8.2");
  EXPECT_EQ(physics->Find("depends_on"), nullptr);
  EXPECT_EQ(physics->Find("volumes")->items()[0].scalar(),
            "../trials/worlds/open_field.yaml:/swarmbox/trials/worlds/open_field.yaml:ro");
  const yaml::Node* lifter = services->Find("lifter");
  ASSERT_NE(lifter->Find("depends_on"), nullptr);
  ASSERT_EQ(lifter->Find("depends_on")->items().size(), 1u);
  EXPECT_EQ(lifter->Find("depends_on")->items()[0].scalar(), "physics");
  EXPECT_EQ(lifter->Find("labels")->Find("swarmbox.component")->scalar(), "lifter");
  EXPECT_EQ(lifter->Find("networks")->Find("mesh")->Find("ipv4_address")->scalar(), "10.200.9.13");
  EXPECT_EQ(physics->Find("tmpfs")->items()[0].scalar(), "/swarmbox/out:mode=1777");
  // The runner's confinement, as compose spells it.
  for (const char* service : {"physics", "lifter"}) {
    SCOPED_TRACE(service);
    const yaml::Node* s = services->Find(service);
    ASSERT_EQ(s->Find("cap_drop")->items().size(), 1u);
    EXPECT_EQ(s->Find("cap_drop")->items()[0].scalar(), "ALL");
    EXPECT_EQ(s->Find("cap_add"), nullptr);
    EXPECT_EQ(s->Find("security_opt")->items()[0].scalar(), "no-new-privileges:true");
    EXPECT_EQ(s->Find("read_only")->scalar(), "true");
    EXPECT_EQ(s->Find("mem_limit")->scalar(), std::to_string(dsl::kDefaultLimits.memory_mib) + "m");
    EXPECT_EQ(s->Find("memswap_limit")->scalar(), std::to_string(dsl::kDefaultLimits.memory_mib) + "m");
    EXPECT_EQ(s->Find("pids_limit")->scalar(), std::to_string(dsl::kDefaultLimits.pids));
  }
  const yaml::Node* lifter_tmpfs = lifter->Find("tmpfs");
  ASSERT_EQ(lifter_tmpfs->items().size(), 2u);
  EXPECT_EQ(lifter_tmpfs->items()[0].scalar(), "/swarmbox/state:mode=1777");  // the Raft WAL
  EXPECT_EQ(lifter_tmpfs->items()[1].scalar(), "/tmp:mode=1777,size=16m");
}

TEST(ComposeYaml, DependsOnTheClosestEarlierPriorityLevel) {
  dsl::Trial t("t");
  t.Add<dsl::Plugin>("a", dsl::ContainerSpec::Image("i"), 1);
  t.Add<dsl::Plugin>("b", dsl::ContainerSpec::Image("i"), 1);
  t.Add<dsl::Plugin>("c", dsl::ContainerSpec::Image("i"), 3);
  t.Add<dsl::Plugin>("d", dsl::ContainerSpec::Image("i"), 5);
  auto doc = yaml::Parse(ComposeYaml(t, {}), "c.yaml");
  ASSERT_TRUE(doc);
  const yaml::Node* s = doc->Find("services");
  EXPECT_EQ(s->Find("a")->Find("depends_on"), nullptr);
  ASSERT_EQ(s->Find("c")->Find("depends_on")->items().size(), 2u);
  EXPECT_EQ(s->Find("c")->Find("depends_on")->items()[1].scalar(), "b");
  ASSERT_EQ(s->Find("d")->Find("depends_on")->items().size(), 1u);
  EXPECT_EQ(s->Find("d")->Find("depends_on")->items()[0].scalar(), "c");
}

}  // namespace
}  // namespace swarmbox::runner
