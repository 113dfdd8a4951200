#include "swarmbox/docker/api_json.hpp"

#include <gtest/gtest.h>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/docker/log_demux.hpp"
#include "test_data.hpp"

namespace swarmbox::docker {
namespace {

using testing::ReadData;

// --- responses recorded from Docker 20.10.24 (API 1.41) ----------------------------------------

TEST(ApiJson, ParsesRecordedVersion) {
  auto v = ParseVersion(ReadData("version.json"));
  ASSERT_TRUE(v) << v.error().ToString();
  EXPECT_EQ(v->api_version, "1.41");
  EXPECT_EQ(v->min_api_version, "1.12");
  EXPECT_EQ(v->version, "20.10.24+dfsg1");
  EXPECT_EQ(v->os, "linux");
  EXPECT_EQ(v->arch, "amd64");
}

TEST(ApiJson, ParsesRecordedImageInspectAndList) {
  auto info = ParseImageInspect(ReadData("image_inspect.json"));
  ASSERT_TRUE(info) << info.error().ToString();
  EXPECT_EQ(info->id, "sha256:a04023193f9b4a5941a5da61c2262c48730cd848bfa15e7d590e5e788bc8886f");
  EXPECT_EQ(info->repo_tags, std::vector<std::string>{"swarmbox-rec/tiny:1"});
  EXPECT_EQ(info->labels.at("swarmbox.test"), "rec");
  EXPECT_GT(info->size_bytes, 1000000);
  EXPECT_EQ(info->created_unix_s, 1795266653);  // 2026-11-21T13:10:53Z

  auto list = ParseImageList(ReadData("image_list.json"));
  ASSERT_TRUE(list) << list.error().ToString();
  ASSERT_EQ(list->size(), 1u);
  EXPECT_EQ((*list)[0].id, info->id);
  EXPECT_EQ((*list)[0].size_bytes, 2354688);
  EXPECT_EQ((*list)[0].created_unix_s, 1795266653);
}

TEST(ApiJson, ParsesRecordedNetworkInspectAndList) {
  auto net = ParseNetwork(ReadData("network_inspect.json"));
  ASSERT_TRUE(net) << net.error().ToString();
  EXPECT_EQ(net->name, "swarmbox-rec-net");
  EXPECT_EQ(net->subnet, "10.213.77.0/24");
  EXPECT_EQ(net->gateway, "10.213.77.1");
  EXPECT_EQ(net->driver, "bridge");
  EXPECT_EQ(net->labels, SwarmboxLabels("rec1", "t1", "mesh"));
  ASSERT_EQ(net->container_ids.size(), 1u);
  EXPECT_EQ(net->container_ids[0].substr(0, 12), "e4e6d991ce6e");

  auto list = ParseNetworkList(ReadData("network_list.json"));
  ASSERT_TRUE(list) << list.error().ToString();
  ASSERT_EQ(list->size(), 1u);
  EXPECT_EQ((*list)[0].id, net->id);
}

TEST(ApiJson, ParsesRecordedContainerInspect) {
  auto c = ParseContainerInspect(ReadData("container_inspect.json"));
  ASSERT_TRUE(c) << c.error().ToString();
  EXPECT_EQ(c->name, "swarmbox-rec-c");
  EXPECT_EQ(c->state.status, "running");
  EXPECT_TRUE(c->state.running);
  EXPECT_GT(c->state.pid, 0);
  EXPECT_FALSE(c->tty);
  EXPECT_EQ(c->labels.at("swarmbox.component"), "probe");
  EXPECT_EQ(c->network_ips.at("swarmbox-rec-net"), "10.213.77.10");
  // Docker's nulls read as "not set".
  EXPECT_TRUE(c->host_config.cap_drop.empty());
  EXPECT_TRUE(c->host_config.security_opt.empty());
  EXPECT_FALSE(c->host_config.read_only_rootfs);
  EXPECT_EQ(c->host_config.pids_limit, 0);
  EXPECT_EQ(c->host_config.memory_bytes, 0);
  EXPECT_EQ(c->host_config.network_mode, "swarmbox-rec-net");
}

TEST(ApiJson, ParsesTheHostConfigOfAHardenedContainer) {
  // The fields as Docker 20.10 answers them for an agent created by the runner.
  auto c = ParseContainerInspect(
      R"({"Id":"abc","Name":"/t1-drone_1","State":{"Status":"exited","OOMKilled":true,"ExitCode":137},)"
      R"("HostConfig":{"NetworkMode":"t1-sim","CapAdd":null,"CapDrop":["ALL"],)"
      R"("SecurityOpt":["no-new-privileges"],"ReadonlyRootfs":true,"Memory":268435456,)"
      R"("PidsLimit":256,"Mounts":[{"Type":"volume","Target":"/swarmbox"},)"
      R"({"Type":"tmpfs","Target":"/tmp","TmpfsOptions":{"SizeBytes":16777216,"Mode":1023}}]}})");
  ASSERT_TRUE(c) << c.error().ToString();
  EXPECT_TRUE(c->state.oom_killed);
  EXPECT_EQ(c->state.exit_code, 137);
  const ContainerHostConfig& h = c->host_config;
  EXPECT_TRUE(h.cap_add.empty());
  EXPECT_EQ(h.cap_drop, std::vector<std::string>{"ALL"});
  EXPECT_EQ(h.security_opt, std::vector<std::string>{"no-new-privileges"});
  EXPECT_TRUE(h.read_only_rootfs);
  EXPECT_EQ(h.memory_bytes, 268435456);
  EXPECT_EQ(h.pids_limit, 256);
  ASSERT_EQ(h.mounts.size(), 2u);
  EXPECT_EQ(h.mounts[0].type, Mount::Type::kVolume);
  EXPECT_EQ(h.mounts[0].target, "/swarmbox");
  EXPECT_EQ(h.mounts[1].type, Mount::Type::kTmpfs);
  EXPECT_EQ(h.mounts[1].tmpfs_size_bytes, 16777216);
  EXPECT_EQ(h.mounts[1].tmpfs_mode, 01777);
}

TEST(ApiJson, ParsesRecordedContainerList) {
  auto list = ParseContainerList(ReadData("container_list.json"));
  ASSERT_TRUE(list) << list.error().ToString();
  ASSERT_EQ(list->size(), 1u);
  EXPECT_EQ((*list)[0].names, std::vector<std::string>{"swarmbox-rec-c"});
  EXPECT_EQ((*list)[0].state, "running");
  EXPECT_EQ((*list)[0].labels.at("swarmbox.run"), "rec1");
}

TEST(ApiJson, ParsesRecordedCreateWaitAndExecAnswers) {
  auto id = ParseIdResponse(ReadData("container_create.json"));
  ASSERT_TRUE(id) << id.error().ToString();
  EXPECT_EQ(id->size(), 64u);
  auto code = ParseWaitResponse(ReadData("wait_response.json"));
  ASSERT_TRUE(code) << code.error().ToString();
  EXPECT_EQ(*code, 137);
  auto exec = ParseExecInspect(ReadData("exec_inspect_exited.json"));
  ASSERT_TRUE(exec) << exec.error().ToString();
  EXPECT_FALSE(exec->running);
  ASSERT_TRUE(exec->exit_code.has_value());
  EXPECT_EQ(*exec->exit_code, 7);
}

TEST(ApiJson, ExecStillRunningHasNoExitCode) {
  auto exec = ParseExecInspect(R"({"ID":"x","Running":true,"ExitCode":null,"Pid":12})");
  ASSERT_TRUE(exec) << exec.error().ToString();
  EXPECT_TRUE(exec->running);
  EXPECT_FALSE(exec->exit_code.has_value());
}

TEST(ApiJson, WaitErrorCarriesDockersMessage) {
  auto code = ParseWaitResponse(R"({"Error":{"Message":"container gone"},"StatusCode":-1})");
  ASSERT_FALSE(code);
  EXPECT_EQ(code.error().message(), "wait failed: container gone");
}

TEST(ApiJson, ParsesRecordedEventStream) {
  const std::string stream = ReadData("events_stream.jsonl");
  LineSplitter splitter;
  std::vector<Event> events;
  splitter.Feed(stream, [&](std::string_view line) {
    auto e = ParseEvent(line);
    ASSERT_TRUE(e) << e.error().ToString();
    events.push_back(*e);
  });
  ASSERT_EQ(events.size(), 4u);
  EXPECT_EQ(events[0].action, "create");
  EXPECT_EQ(events[1].action, "start");
  EXPECT_EQ(events[2].action, "die");
  EXPECT_EQ(events[2].attributes.at("exitCode"), "3");
  EXPECT_EQ(events[3].action, "destroy");
  EXPECT_EQ(events[0].type, "container");
  EXPECT_EQ(events[0].attributes.at("swarmbox.run"), "rec2");
  EXPECT_GT(events[0].time_unix_ns, 1700000000LL * 1000000000LL);
}

TEST(ApiJson, ParsesRecordedBuildStreams) {
  LineSplitter splitter;
  std::vector<BuildMessage> ok;
  splitter.Feed(ReadData("build_stream_ok.jsonl"), [&](std::string_view line) {
    auto m = ParseBuildLine(line);
    ASSERT_TRUE(m) << m.error().ToString();
    ok.push_back(*m);
  });
  ASSERT_FALSE(ok.empty());
  EXPECT_EQ(ok[0].stream, "Step 1/4 : FROM scratch");
  std::string aux;
  for (const auto& m : ok) {
    EXPECT_TRUE(m.error.empty());
    if (!m.aux_id.empty()) aux = m.aux_id;
  }
  EXPECT_EQ(aux, "sha256:886c34552467c304d9eea14dc8985cf16b21d3a66233977ee40602bccfd1b387");

  std::string error;
  splitter.Feed(ReadData("build_stream_error.jsonl"), [&](std::string_view line) {
    if (line.empty() || line.front() != '{') return;  // the recording ends with curl's status
    auto m = ParseBuildLine(line);
    ASSERT_TRUE(m) << m.error().ToString();
    if (!m->error.empty()) error = m->error;
  });
  EXPECT_EQ(error,
            "COPY failed: file not found in build context or excluded by .dockerignore: stat "
            "missing-file: file does not exist");
}

TEST(ApiJson, MapsRecordedErrorsToTypedErrorsWithTheEndpoint) {
  Error e = HttpStatusError(404, ReadData("error_no_such_container.json"),
                            "GET /v1.41/containers/nope-nothing/json", false);
  EXPECT_EQ(e.code(), ErrorCode::kNotFound);
  EXPECT_EQ(e.message(), "HTTP 404: No such container: nope-nothing");
  EXPECT_EQ(e.where(), "GET /v1.41/containers/nope-nothing/json");

  Error conflict = HttpStatusError(409, ReadData("error_container_name_conflict.json"),
                                   "POST /v1.41/containers/create", true);
  EXPECT_EQ(conflict.code(), ErrorCode::kAlreadyExists);
  EXPECT_NE(conflict.message().find("is already in use"), std::string::npos);

  Error state = HttpStatusError(409, ReadData("error_kill_not_running.json"),
                                "POST /v1.41/containers/x/kill", false);
  EXPECT_EQ(state.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(state.message().find("is not running"), std::string::npos);

  Error net = HttpStatusError(409, ReadData("error_network_conflict.json"),
                              "POST /v1.41/networks/create", true);
  EXPECT_EQ(net.code(), ErrorCode::kAlreadyExists);
  EXPECT_EQ(net.message(), "HTTP 409: network with name swarmbox-rec-net already exists");

  EXPECT_EQ(HttpStatusError(500, "boom\n", "x", false).message(), "HTTP 500: boom");
  EXPECT_EQ(HttpStatusError(500, "boom\n", "x", false).code(), ErrorCode::kInternal);
  EXPECT_EQ(HttpStatusError(503, "", "x", false).code(), ErrorCode::kUnavailable);
  EXPECT_EQ(HttpStatusError(503, "", "x", false).message(), "HTTP 503: (no message)");
}

TEST(ApiJson, RejectsMalformedAnswers) {
  auto bad = ParseContainerInspect("{\"Id\": [unclosed");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code(), ErrorCode::kProtocol);
  EXPECT_NE(bad.error().message().find("unparseable JSON in container inspect"), std::string::npos);
  auto no_id = ParseIdResponse("{\"Warnings\":[]}");
  ASSERT_FALSE(no_id);
  EXPECT_EQ(no_id.error().message(), "create response: expected Id in Docker's answer");
  auto v = ParseApiVersion("1.x");
  ASSERT_FALSE(v);
  EXPECT_EQ(v.error().message(), "malformed API version '1.x'");
}

// --- requests ------------------------------------------------------------------------------------

TEST(ApiJson, ComparesApiVersions) {
  EXPECT_LT(*ParseApiVersion("1.41"), *ParseApiVersion("1.44"));
  EXPECT_LT(*ParseApiVersion("1.9"), *ParseApiVersion("1.10"));
  EXPECT_EQ(ParseApiVersion("1.41")->ToString(), "1.41");
}

TEST(ApiJson, EncodesFiltersAndQueries) {
  LabelSelector sel;
  sel.equals = {{"swarmbox.run", "r1"}, {"swarmbox.trial", ""}};
  EXPECT_EQ(FiltersJson(sel, {{"type", {"container"}}}),
            R"({"label":["swarmbox.run=r1","swarmbox.trial"],"type":["container"]})");
  EXPECT_EQ(UrlEncode("a b/c:d={}"), "a%20b%2Fc%3Ad%3D%7B%7D");
  BuildRequest b;
  b.tags = {"swarmbox/agent:00ff"};
  b.labels = {{"swarmbox.component", "agent"}};
  EXPECT_EQ(BuildQuery(b),
            "?dockerfile=Dockerfile&t=swarmbox%2Fagent%3A00ff&labels=%7B%22swarmbox.component%22%3A%"
            "22agent%22%7D&rm=1&forcerm=1");
}

TEST(ApiJson, BuildsNetworkBodyWithExplicitSubnet) {
  NetworkSpec spec;
  spec.name = "t1-mesh";
  spec.subnet = "10.77.2.0/24";
  spec.gateway = "10.77.2.1";
  spec.labels = SwarmboxLabels("r1", "t1", "mesh");
  EXPECT_EQ(CreateNetworkBody(spec),
            R"({"Name":"t1-mesh","CheckDuplicate":true,"Driver":"bridge","Internal":false,)"
            R"("Attachable":true,"Labels":{"swarmbox.component":"mesh","swarmbox.run":"r1",)"
            R"("swarmbox.trial":"t1"},"IPAM":{"Driver":"default","Config":[{"Subnet":"10.77.2.0/24",)"
            R"("Gateway":"10.77.2.1"}]}})");
}

TEST(ApiJson, BuildsConnectBodyWithFixedAddress) {
  EndpointSpec e;
  e.network = "t1-mesh";
  e.ipv4_address = "10.77.2.11";
  e.aliases = {"drone_1"};
  EXPECT_EQ(ConnectNetworkBody(e, "abc"),
            R"({"Container":"abc","EndpointConfig":{"IPAMConfig":{"IPv4Address":"10.77.2.11"},)"
            R"("Aliases":["drone_1"]}})");
}

ContainerSpec AgentSpec() {
  ContainerSpec spec;
  spec.name = "t1-drone_1";
  spec.image = "swarmbox/agent:00ff";
  spec.cmd = {"--name", "drone_1", "--seed", "42"};
  spec.env = {{"SWARMBOX_RUN", "r1"}, {"DOMAIN", "7"}};
  spec.user = "1000:1000";
  spec.labels = SwarmboxLabels("r1", "t1", "drone_1");
  spec.mounts = {{Mount::Type::kBind, "/host/out", "/out", false, 0},
                 {Mount::Type::kTmpfs, "", "/scratch", false, 1 << 20, 01777},
                 {Mount::Type::kVolume, "", "/swarmbox", false, 0, 0}};
  spec.security_opt = {"no-new-privileges"};
  spec.read_only_rootfs = true;
  EndpointSpec sim;
  sim.network = "t1-sim";
  sim.ipv4_address = "10.77.1.11";
  EndpointSpec mesh;
  mesh.network = "t1-mesh";
  mesh.ipv4_address = "10.77.2.11";
  spec.networks = {sim, mesh};
  spec.cap_drop = {"ALL"};
  spec.resources.memory_bytes = 256 << 20;
  spec.resources.nano_cpus = 500000000;
  spec.resources.pids_limit = 64;
  return spec;
}

TEST(ApiJson, ContainerBodyPutsOnlyTheFirstNetworkAtCreateBelowApi144) {
  auto doc = yaml::Parse(CreateContainerBody(AgentSpec(), /*all_networks=*/false));
  ASSERT_TRUE(doc) << doc.error().ToString();
  const yaml::Node& n = *doc;
  EXPECT_EQ(n.Find("Image")->scalar(), "swarmbox/agent:00ff");
  EXPECT_EQ(n.Find("User")->scalar(), "1000:1000");
  ASSERT_EQ(n.Find("Cmd")->items().size(), 4u);
  EXPECT_EQ(n.Find("Cmd")->items()[3].scalar(), "42");
  EXPECT_TRUE(n.Find("Cmd")->items()[3].quoted());  // argv stays a string
  EXPECT_EQ(n.Find("Env")->items()[0].scalar(), "DOMAIN=7");
  EXPECT_EQ(n.Find("Labels")->Find("swarmbox.component")->scalar(), "drone_1");
  const yaml::Node* host = n.Find("HostConfig");
  ASSERT_NE(host, nullptr);
  EXPECT_EQ(host->Find("NetworkMode")->scalar(), "t1-sim");
  EXPECT_EQ(host->Find("Memory")->scalar(), std::to_string(256 << 20));
  EXPECT_EQ(host->Find("MemorySwap")->scalar(), std::to_string(256 << 20));
  EXPECT_EQ(host->Find("NanoCpus")->scalar(), "500000000");
  EXPECT_EQ(host->Find("PidsLimit")->scalar(), "64");
  EXPECT_EQ(host->Find("CapDrop")->items()[0].scalar(), "ALL");
  EXPECT_EQ(host->Find("Mounts")->items()[0].Find("Type")->scalar(), "bind");
  EXPECT_EQ(host->Find("Mounts")->items()[1].Find("TmpfsOptions")->Find("SizeBytes")->scalar(),
            "1048576");
  EXPECT_EQ(host->Find("Mounts")->items()[1].Find("TmpfsOptions")->Find("Mode")->scalar(), "1023");
  // An anonymous volume: no Source, so Docker creates one (removed with the container's v=1).
  EXPECT_EQ(host->Find("Mounts")->items()[2].Find("Type")->scalar(), "volume");
  EXPECT_EQ(host->Find("Mounts")->items()[2].Find("Source")->scalar(), "");
  EXPECT_EQ(host->Find("SecurityOpt")->items().size(), 1u);
  EXPECT_EQ(host->Find("SecurityOpt")->items()[0].scalar(), "no-new-privileges");
  EXPECT_EQ(host->Find("ReadonlyRootfs")->scalar(), "true");
  const yaml::Node* endpoints = n.Find("NetworkingConfig")->Find("EndpointsConfig");
  ASSERT_EQ(endpoints->entries().size(), 1u);
  EXPECT_EQ(endpoints->Find("t1-sim")->Find("IPAMConfig")->Find("IPv4Address")->scalar(),
            "10.77.1.11");
}

TEST(ApiJson, ContainerBodyPutsAllNetworksAtCreateFromApi144) {
  auto doc = yaml::Parse(CreateContainerBody(AgentSpec(), /*all_networks=*/true));
  ASSERT_TRUE(doc) << doc.error().ToString();
  const yaml::Node* endpoints = doc->Find("NetworkingConfig")->Find("EndpointsConfig");
  ASSERT_EQ(endpoints->entries().size(), 2u);
  EXPECT_EQ(endpoints->Find("t1-mesh")->Find("IPAMConfig")->Find("IPv4Address")->scalar(),
            "10.77.2.11");
}

TEST(ApiJson, SidecarSharesTheAgentsNetworkNamespace) {
  ContainerSpec spec;
  spec.image = "swarmbox/faults:1";
  spec.network_mode = "container:abc";
  spec.cap_add = {"NET_ADMIN"};
  auto doc = yaml::Parse(CreateContainerBody(spec, false));
  ASSERT_TRUE(doc) << doc.error().ToString();
  EXPECT_EQ(doc->Find("HostConfig")->Find("NetworkMode")->scalar(), "container:abc");
  EXPECT_EQ(doc->Find("HostConfig")->Find("CapAdd")->items()[0].scalar(), "NET_ADMIN");
  EXPECT_EQ(doc->Find("NetworkingConfig"), nullptr);
}

// A published port (swarmbox run --view): exposed, and bound to the host address and port.
TEST(ApiJson, PublishesPortsOnTheHost) {
  ContainerSpec spec;
  spec.image = "swarmbox/physics:1";
  spec.ports = {{8765, "127.0.0.1", 9000}};
  auto doc = yaml::Parse(CreateContainerBody(spec, false));
  ASSERT_TRUE(doc) << doc.error().ToString();
  ASSERT_NE(doc->Find("ExposedPorts"), nullptr);
  EXPECT_NE(doc->Find("ExposedPorts")->Find("8765/tcp"), nullptr);
  const yaml::Node* b = doc->Find("HostConfig")->Find("PortBindings")->Find("8765/tcp");
  ASSERT_NE(b, nullptr);
  ASSERT_EQ(b->items().size(), 1u);
  EXPECT_EQ(b->items()[0].Find("HostIp")->scalar(), "127.0.0.1");
  EXPECT_EQ(b->items()[0].Find("HostPort")->scalar(), "9000");
  EXPECT_EQ(yaml::Parse(CreateContainerBody(ContainerSpec{}, false))->Find("ExposedPorts"), nullptr);
}

TEST(ApiJson, BuildsExecBodies) {
  ExecSpec spec;
  spec.cmd = {"/probe", "exit", "7"};
  spec.user = "1000";
  EXPECT_EQ(ExecCreateBody(spec),
            R"({"AttachStdin":false,"AttachStdout":true,"AttachStderr":true,"Tty":false,)"
            R"("Cmd":["/probe","exit","7"],"User":"1000","Privileged":false})");
  EXPECT_EQ(ExecStartBody(false), R"({"Detach":false,"Tty":false})");
}

}  // namespace
}  // namespace swarmbox::docker
