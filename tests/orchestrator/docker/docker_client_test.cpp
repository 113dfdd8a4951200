// DockerClient against a scripted transport that replays recorded engine answers: checks what the
// client sends (endpoints, version prefix, bodies) and how it maps answers and errors.
#include "swarmbox/docker/docker_client.hpp"

#include <gtest/gtest.h>

#include <deque>

#include "test_data.hpp"

namespace swarmbox::docker {
namespace {

using testing::ReadData;

struct Scripted {
  std::string expect;  // "METHOD target-prefix"
  HttpResponse response;
  std::vector<std::string> chunks;  // streamed 2xx body pieces
};

class ScriptedTransport : public HttpTransport {
 public:
  Result<HttpResponse> Send(const HttpRequest& request, const BodyChunkFn& on_chunk,
                            CancelToken* /*cancel*/) override {
    sent.push_back(request);
    if (script.empty()) {
      ADD_FAILURE() << "unexpected request " << request.method << " " << request.target;
      return Error(ErrorCode::kInternal, "script exhausted");
    }
    Scripted s = script.front();
    script.pop_front();
    const std::string got = request.method + " " + request.target;
    EXPECT_EQ(got.rfind(s.expect, 0), 0u) << "expected " << s.expect << ", got " << got;
    if (on_chunk && s.response.success()) {
      for (const std::string& c : s.chunks) on_chunk(c);
    } else {
      for (const std::string& c : s.chunks) s.response.body += c;
    }
    return s.response;
  }
  std::string endpoint() const override { return "unix:///scripted.sock"; }

  void Add(std::string expect, int status, std::string body = {},
           std::vector<std::string> chunks = {}, std::map<std::string, std::string> headers = {}) {
    Scripted s;
    s.expect = std::move(expect);
    s.response.status = status;
    s.response.body = std::move(body);
    s.response.headers = std::move(headers);
    s.chunks = std::move(chunks);
    script.push_back(std::move(s));
  }

  std::deque<Scripted> script;
  std::vector<HttpRequest> sent;
};

class DockerClientTest : public ::testing::Test {
 protected:
  // Connects with the engine announcing `api` in /_ping.
  std::unique_ptr<DockerClient> Connect(std::string api = "1.41") {
    auto t = std::make_unique<ScriptedTransport>();
    transport_ = t.get();
    t->Add("GET /_ping", 200, "OK", {}, {{"api-version", api}});
    auto c = DockerClient::Connect(std::move(t), std::chrono::seconds(5));
    EXPECT_TRUE(c) << c.error().ToString();
    return c ? std::move(*c) : nullptr;
  }
  ScriptedTransport* transport_ = nullptr;
};

TEST_F(DockerClientTest, NegotiatesTheEnginesVersionFromPing) {
  auto c = Connect("1.41");
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->api_version(), "1.41");
  auto newer = Connect("1.47");
  ASSERT_NE(newer, nullptr);
  EXPECT_EQ(newer->api_version(), "1.44");  // never above what we know
}

TEST_F(DockerClientTest, RefusesTooOldEngines) {
  auto t = std::make_unique<ScriptedTransport>();
  t->Add("GET /_ping", 200, "OK", {}, {{"api-version", "1.30"}});
  auto c = DockerClient::Connect(std::move(t), std::chrono::seconds(5));
  ASSERT_FALSE(c);
  EXPECT_EQ(c.error().message(), "the engine speaks Docker API 1.30; SwarmBox needs 1.40 or newer");
  EXPECT_EQ(c.error().where(), "GET /_ping (unix:///scripted.sock)");
}

TEST_F(DockerClientTest, FallsBackToVersionWhenPingHasNoHeader) {
  auto t = std::make_unique<ScriptedTransport>();
  t->Add("GET /_ping", 200, "OK");
  t->Add("GET /version", 200, ReadData("version.json"));
  auto c = DockerClient::Connect(std::move(t), std::chrono::seconds(5));
  ASSERT_TRUE(c) << c.error().ToString();
  EXPECT_EQ((*c)->api_version(), "1.41");
}

TEST_F(DockerClientTest, ConnectsSecondNetworkBeforeStartOnApi141) {
  auto c = Connect("1.41");
  transport_->Add("POST /v1.41/containers/create?name=t1-drone_1", 201,
                  ReadData("container_create.json"));
  transport_->Add("POST /v1.41/networks/t1-mesh/connect", 200);
  ContainerSpec spec;
  spec.name = "t1-drone_1";
  spec.image = "img";
  spec.networks.resize(2);
  spec.networks[0].network = "t1-sim";
  spec.networks[0].ipv4_address = "10.77.1.11";
  spec.networks[1].network = "t1-mesh";
  spec.networks[1].ipv4_address = "10.77.2.11";
  auto id = c->CreateContainer(spec);
  ASSERT_TRUE(id) << id.error().ToString();
  EXPECT_EQ(id->substr(0, 12), "e4e6d991ce6e");
  ASSERT_EQ(transport_->sent.size(), 3u);
  EXPECT_EQ(transport_->sent[1].content_type, "application/json");
  EXPECT_NE(transport_->sent[1].body.find("\"t1-sim\":{\"IPAMConfig\""), std::string::npos);
  EXPECT_EQ(transport_->sent[1].body.find("t1-mesh"), std::string::npos);
  EXPECT_NE(transport_->sent[2].body.find("\"IPv4Address\":\"10.77.2.11\""), std::string::npos);
  EXPECT_NE(transport_->sent[2].body.find(*id), std::string::npos);
}

TEST_F(DockerClientTest, RemovesTheContainerWhenConnectingFails) {
  auto c = Connect("1.41");
  transport_->Add("POST /v1.41/containers/create", 201, ReadData("container_create.json"));
  transport_->Add("POST /v1.41/networks/t1-mesh/connect", 404,
                  R"({"message":"network t1-mesh not found"})");
  transport_->Add("DELETE /v1.41/containers/e4e6d991ce6e", 204);
  ContainerSpec spec;
  spec.image = "img";
  spec.networks.resize(2);
  spec.networks[0].network = "t1-sim";
  spec.networks[1].network = "t1-mesh";
  auto id = c->CreateContainer(spec);
  ASSERT_FALSE(id);
  EXPECT_EQ(id.error().code(), ErrorCode::kNotFound);
  EXPECT_EQ(id.error().message(),
            "connecting the new container to network t1-mesh: HTTP 404: network t1-mesh not found");
  EXPECT_EQ(id.error().where(), "POST /v1.41/networks/t1-mesh/connect (unix:///scripted.sock)");
  EXPECT_TRUE(transport_->script.empty());
}

TEST_F(DockerClientTest, AllNetworksAtCreateFromApi144) {
  auto c = Connect("1.44");
  transport_->Add("POST /v1.44/containers/create", 201, ReadData("container_create.json"));
  ContainerSpec spec;
  spec.image = "img";
  spec.networks.resize(2);
  spec.networks[0].network = "a";
  spec.networks[1].network = "b";
  ASSERT_TRUE(c->CreateContainer(spec));
  EXPECT_TRUE(transport_->script.empty());
}

TEST_F(DockerClientTest, ErrorsNameTheEndpointAndCarryDockersMessage) {
  auto c = Connect();
  transport_->Add("GET /v1.41/containers/nope-nothing/json", 404,
                  ReadData("error_no_such_container.json"));
  auto info = c->InspectContainer("nope-nothing");
  ASSERT_FALSE(info);
  EXPECT_EQ(info.error().code(), ErrorCode::kNotFound);
  EXPECT_EQ(info.error().ToString(),
            "GET /v1.41/containers/nope-nothing/json (unix:///scripted.sock): HTTP 404: No such "
            "container: nope-nothing");
}

TEST_F(DockerClientTest, StartingAStartedContainerSucceeds) {
  auto c = Connect();
  transport_->Add("POST /v1.41/containers/x/start", 304);
  EXPECT_TRUE(c->StartContainer("x"));
  transport_->Add("POST /v1.41/containers/x/stop?t=3", 304);
  EXPECT_TRUE(c->StopContainer("x", 3));
  ASSERT_EQ(transport_->sent.size(), 3u);
  EXPECT_EQ(transport_->sent[2].timeout, std::chrono::seconds(8));  // request limit + grace
}

TEST_F(DockerClientTest, BuildErrorInsideTheStreamBecomesAnError) {
  auto c = Connect();
  std::string stream = ReadData("build_stream_error.jsonl");
  stream = stream.substr(0, stream.rfind("\nHTTP"));  // drop curl's status line of the recording
  // Deliver in awkward chunks: JSON objects split across reads.
  std::vector<std::string> chunks;
  for (std::size_t i = 0; i < stream.size(); i += 7) chunks.push_back(stream.substr(i, 7));
  transport_->Add("POST /v1.41/build?dockerfile=Dockerfile&t=swarmbox%2Fbad%3A1", 200, {}, chunks);
  BuildRequest req;
  req.context_tar = "tar bytes";
  req.tags = {"swarmbox/bad:1"};
  std::vector<std::string> progress;
  auto r = c->BuildImage(req, [&](std::string_view l) { progress.emplace_back(l); }, nullptr);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(r.error().message(),
            "image build failed: COPY failed: file not found in build context or excluded by "
            ".dockerignore: stat missing-file: file does not exist");
  EXPECT_EQ(r.error().where(), "POST /v1.41/build (unix:///scripted.sock)");
  ASSERT_GE(progress.size(), 2u);
  EXPECT_EQ(progress[0], "Step 1/2 : FROM scratch");
  EXPECT_EQ(transport_->sent[1].content_type, "application/x-tar");
  EXPECT_EQ(transport_->sent[1].body, "tar bytes");
}

TEST_F(DockerClientTest, BuildReturnsTheImageIdFromTheStream) {
  auto c = Connect();
  transport_->Add("POST /v1.41/build", 200, {}, {ReadData("build_stream_ok.jsonl")});
  BuildRequest req;
  req.tags = {"swarmbox-rec/tiny:2"};
  std::vector<std::string> progress;
  auto r = c->BuildImage(req, [&](std::string_view l) { progress.emplace_back(l); }, nullptr);
  ASSERT_TRUE(r) << r.error().ToString();
  EXPECT_EQ(r->image_id, "sha256:886c34552467c304d9eea14dc8985cf16b21d3a66233977ee40602bccfd1b387");
  EXPECT_EQ(progress.back(), "Successfully tagged swarmbox-rec/tiny:2");
}

TEST_F(DockerClientTest, FollowLogsDemultiplexesByTheContainersTtySetting) {
  auto c = Connect();
  transport_->Add("GET /v1.41/containers/c1/json", 200, ReadData("container_inspect.json"));
  const std::string logs = ReadData("logs_multiplexed.bin");
  std::vector<std::string> chunks;
  for (char ch : logs) chunks.emplace_back(1, ch);  // one byte at a time
  transport_->Add("GET /v1.41/containers/c1/logs?follow=1&stdout=1&stderr=1", 200, {}, chunks);
  std::vector<std::string> lines;
  Status s = c->FollowLogs("c1", {}, [&](const LogLine& l) { lines.push_back(l.text); }, nullptr);
  ASSERT_TRUE(s) << s.error().ToString();
  EXPECT_EQ(lines, (std::vector<std::string>{"out1", "out2", "err1"}));
}

TEST_F(DockerClientTest, RefusesToFollowANeverStartedContainer) {
  auto c = Connect();
  std::string created = ReadData("container_inspect.json");
  const std::string running = "\"Status\":\"running\"";
  ASSERT_NE(created.find(running), std::string::npos);
  created.replace(created.find(running), running.size(), "\"Status\":\"created\"");
  transport_->Add("GET /v1.41/containers/c1/json", 200, created);
  Status s = c->FollowLogs("c1", {}, [](const LogLine&) {}, nullptr);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(s.error().message().find("follow its logs after StartContainer"), std::string::npos);
}

TEST_F(DockerClientTest, ExecReportsOutputAndExitCode) {
  auto c = Connect();
  transport_->Add("POST /v1.41/containers/c1/exec", 201, ReadData("exec_create.json"));
  transport_->Add("GET /v1.41/exec/", 200,
                  R"({"ID":"x","Running":false,"ExitCode":0,"ProcessConfig":{"tty":false},"Pid":0})");
  transport_->Add("POST /v1.41/exec/", 200, {}, {ReadData("exec_start_output.bin")});
  transport_->Add("GET /v1.41/exec/", 200, ReadData("exec_inspect_exited.json"));
  ExecSpec spec;
  spec.cmd = {"/bin/sh", "-c", "echo hi; exit 7"};
  auto id = c->CreateExec("c1", spec);
  ASSERT_TRUE(id) << id.error().ToString();
  std::vector<std::string> lines;
  ASSERT_TRUE(c->StartExec(*id, [&](const LogLine& l) { lines.push_back(l.text); }, nullptr));
  EXPECT_EQ(lines, std::vector<std::string>{"hi"});
  auto state = c->InspectExec(*id);
  ASSERT_TRUE(state) << state.error().ToString();
  EXPECT_EQ(state->exit_code.value_or(-1), 7);
}

TEST_F(DockerClientTest, RejectsAnExecWithoutCommand) {
  auto c = Connect();
  auto id = c->CreateExec("c1", ExecSpec{});
  ASSERT_FALSE(id);
  EXPECT_EQ(id.error().message(), "exec needs a command");
}

TEST_F(DockerClientTest, SidecarCannotAlsoJoinNetworks) {
  auto c = Connect();
  ContainerSpec spec;
  spec.image = "img";
  spec.network_mode = "container:agent";
  spec.networks.resize(1);
  spec.networks[0].network = "mesh";
  auto id = c->CreateContainer(spec);
  ASSERT_FALSE(id);
  EXPECT_EQ(id.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(id.error().message().find("cannot join networks of its own"), std::string::npos);
}

TEST_F(DockerClientTest, StreamsEventsWithLabelFilters) {
  auto c = Connect();
  transport_->Add("GET /v1.41/events?filters=", 200, {}, {ReadData("events_stream.jsonl")});
  EventFilter f;
  f.labels.equals = {{"swarmbox.run", "rec2"}};
  f.types = {"container"};
  std::vector<std::string> actions;
  ASSERT_TRUE(c->StreamEvents(f, [&](const Event& e) { actions.push_back(e.action); }, nullptr));
  EXPECT_EQ(actions, (std::vector<std::string>{"create", "start", "die", "destroy"}));
  EXPECT_NE(transport_->sent[1].target.find("swarmbox.run%3Drec2"), std::string::npos);
}

TEST(UnixSocketTransport, ReportsAMissingEngineAsUnavailable) {
  UnixSocketTransport t("/nonexistent/docker.sock");
  HttpRequest req;
  req.target = "/_ping";
  auto r = t.Send(req, nullptr, nullptr);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), ErrorCode::kUnavailable);
  EXPECT_NE(r.error().message().find("no Docker engine answers at /nonexistent/docker.sock"),
            std::string::npos);
  EXPECT_EQ(r.error().where(), "GET /_ping (unix:///nonexistent/docker.sock)");
}

TEST(UnixSocketTransport, HonoursACancelledToken) {
  UnixSocketTransport t("/nonexistent/docker.sock");
  CancelToken cancel;
  cancel.Cancel();
  HttpRequest req;
  req.target = "/_ping";
  auto r = t.Send(req, nullptr, &cancel);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), ErrorCode::kCancelled);
}

}  // namespace
}  // namespace swarmbox::docker
