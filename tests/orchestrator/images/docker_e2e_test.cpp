// End to end against the real engine (label e2e, RESOURCE_LOCK docker): a registry-free image of a
// program of this tree, a labelled network with an explicit subnet, a non-root container on it
// with a fixed address, logs followed as a stream, exec with exit code, files through the archive
// endpoint, wait, removal; and RemoveLabelled (the basis of `swarmbox gc`).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <iostream>
#include <thread>

#include "e2e_support.hpp"
#include "probe_image.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/docker/tar_archive.hpp"
#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/image_spec.hpp"

namespace swarmbox {
namespace {

using docker::ContainerSpec;
using docker::LabelSelector;
using Clock = std::chrono::steady_clock;

double Ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

class DockerEndToEnd : public ::testing::Test {
 protected:
  void SetUp() override {
    api_ = testing::ConnectOrFail();
    ASSERT_NE(api_, nullptr);
    run_id_ = testing::UniqueRunId("e2e");
    auto image = images::EnsureImage(*api_, testing::ProbeImageSpec(), nullptr, nullptr);
    ASSERT_TRUE(image) << image.error().ToString();
    image_ = *image;
  }
  void TearDown() override {
    if (api_ == nullptr) return;
    LabelSelector run;
    run.equals = {{std::string(docker::kLabelRun), run_id_}};
    auto left = docker::RemoveLabelled(*api_, run, false);
    EXPECT_TRUE(left) << left.error().ToString();
  }

  ContainerSpec ProbeContainer(const std::string& component, std::vector<std::string> cmd) {
    ContainerSpec spec;
    spec.name = "sbx-" + run_id_ + "-" + component;
    spec.image = image_.tag;
    spec.cmd = std::move(cmd);
    spec.user = "1000:1000";
    spec.labels = docker::SwarmboxLabels(run_id_, "t1", component);
    spec.cap_drop = {"ALL"};
    return spec;
  }

  std::unique_ptr<docker::DockerClient> api_;
  std::string run_id_;
  images::EnsuredImage image_;
};

TEST_F(DockerEndToEnd, UnchangedImageIsNotRebuilt) {
  auto again = images::EnsureImage(*api_, testing::ProbeImageSpec(), nullptr, nullptr);
  ASSERT_TRUE(again) << again.error().ToString();
  EXPECT_FALSE(again->built);
  EXPECT_EQ(again->tag, image_.tag);
  EXPECT_EQ(again->image_id, image_.image_id);
  // Older content hashes of the probe (earlier builds of the tree) go; this one stays.
  auto stale = images::RemoveStaleImages(*api_, "swarmbox/e2e-probe", image_.tag);
  ASSERT_TRUE(stale) << stale.error().ToString();
  auto still = api_->InspectImage(image_.tag);
  EXPECT_TRUE(still) << still.error().ToString();
  docker::LabelSelector probe_images;
  probe_images.equals = {{"swarmbox.image", "swarmbox/e2e-probe"}};
  auto left = api_->ListImages(probe_images);
  ASSERT_TRUE(left) << left.error().ToString();
  EXPECT_EQ(left->size(), 1u);
  std::cout << "[figures] probe image " << image_.tag << ": " << image_.image_size_bytes
            << " bytes, context " << image_.context_bytes << " bytes, pack " << image_.pack_s * 1e3
            << " ms" << (image_.built ? ", build " + std::to_string(image_.build_s * 1e3) + " ms" : "")
            << "; cached check " << (again->pack_s * 1e3) << " ms pack + inspect\n";
}

TEST_F(DockerEndToEnd, BuildsRunsStreamsExecsCopiesAndRemoves) {
  // A labelled network with an explicit subnet.
  docker::NetworkSpec net;
  net.name = "sbx-" + run_id_ + "-mesh";
  net.labels = docker::SwarmboxLabels(run_id_, "t1", "mesh");
  std::string prefix;
  auto net_id = testing::CreateFreeNetwork(*api_, net, &prefix);
  ASSERT_TRUE(net_id) << net_id.error().ToString();
  auto net_info = api_->InspectNetwork(*net_id);
  ASSERT_TRUE(net_info) << net_info.error().ToString();
  EXPECT_EQ(net_info->subnet, prefix + "0/24");
  EXPECT_EQ(net_info->labels.at("swarmbox.component"), "mesh");

  // A non-root container on it with a fixed address.
  ContainerSpec spec = ProbeContainer("probe", {"serve", "5"});
  spec.networks = {docker::EndpointSpec{net.name, prefix + "10", {"probe"}}};
  const auto t_create = Clock::now();
  auto id = api_->CreateContainer(spec);
  ASSERT_TRUE(id) << id.error().ToString();
  ASSERT_TRUE(api_->StartContainer(*id));

  // Logs as a live stream, on its own thread as the runner does.
  testing::LineLog log;
  Status follow_status = Ok{};
  std::thread follower([&] { follow_status = api_->FollowLogs(*id, {}, log.Collector(), nullptr); });
  ASSERT_TRUE(log.WaitFor("probe ready uid=1000 gid=1000", std::chrono::seconds(10))) << log.Dump();
  const double create_to_first_line_ms = Ms(log.first_line_at() - t_create);
  // stdout and stderr are copied by separate goroutines in the engine: wait for both ends.
  ASSERT_TRUE(log.WaitFor("warn 4", std::chrono::seconds(10))) << log.Dump();
  ASSERT_TRUE(log.WaitFor("tick 4", std::chrono::seconds(10))) << log.Dump();
  for (const auto& l : log.lines()) {
    if (l.text.rfind("warn", 0) == 0) {
      EXPECT_EQ(l.stream, docker::StreamKind::kStderr) << l.text;
    }
    if (l.text.rfind("tick", 0) == 0) {
      EXPECT_EQ(l.stream, docker::StreamKind::kStdout) << l.text;
    }
  }

  auto info = api_->InspectContainer(*id);
  ASSERT_TRUE(info) << info.error().ToString();
  EXPECT_TRUE(info->state.running);
  EXPECT_EQ(info->network_ips.at(net.name), prefix + "10");
  for (const auto& [key, value] : docker::SwarmboxLabels(run_id_, "t1", "probe")) {
    EXPECT_EQ(info->labels.at(key), value) << key;  // plus the image's own labels
  }

  // Exec: output and exit code.
  docker::ExecSpec exec;
  exec.cmd = {"/usr/local/bin/swarmbox-probe", "exit", "7"};
  auto exec_id = api_->CreateExec(*id, exec);
  ASSERT_TRUE(exec_id) << exec_id.error().ToString();
  testing::LineLog exec_log;
  ASSERT_TRUE(api_->StartExec(*exec_id, exec_log.Collector(), nullptr));
  EXPECT_TRUE(exec_log.Has("exec uid=1000")) << exec_log.Dump();
  auto exec_state = api_->InspectExec(*exec_id);
  ASSERT_TRUE(exec_state) << exec_state.error().ToString();
  EXPECT_FALSE(exec_state->running);
  EXPECT_EQ(exec_state->exit_code.value_or(-1), 7);

  // Archive: put a file and get it back.
  docker::TarWriter note;
  ASSERT_TRUE(note.AddFile("note.txt", "written through PUT /archive\n"));
  auto note_tar = note.Finish();
  ASSERT_TRUE(note_tar);
  ASSERT_TRUE(api_->PutArchive(*id, "/tmp", *note_tar));
  auto got = api_->GetArchive(*id, "/tmp/note.txt");
  ASSERT_TRUE(got) << got.error().ToString();
  auto entries = docker::ReadTar(*got);
  ASSERT_TRUE(entries) << entries.error().ToString();
  ASSERT_EQ(entries->size(), 1u);
  EXPECT_EQ((*entries)[0].path, "note.txt");
  EXPECT_EQ((*entries)[0].content, "written through PUT /archive\n");
  auto missing = api_->GetArchive(*id, "/tmp/absent");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code(), ErrorCode::kNotFound);
  EXPECT_NE(missing.error().where().find("/archive"), std::string::npos);

  // The stop file ends the program: wait gives its exit code and the log stream ends by itself.
  docker::TarWriter stop;
  ASSERT_TRUE(stop.AddFile("stop", "bye\n"));
  auto stop_tar = stop.Finish();
  ASSERT_TRUE(stop_tar);
  const auto t_stop_file = Clock::now();  // from sending the file (the PUT included)
  ASSERT_TRUE(api_->PutArchive(*id, "/tmp", *stop_tar));
  // The program polls for the file every 20 ms; its line must reach us live, well under a second.
  ASSERT_TRUE(log.WaitFor("stopping: bye", std::chrono::seconds(5))) << log.Dump();
  const double line_latency_ms = Ms(Clock::now() - t_stop_file);
  EXPECT_LT(line_latency_ms, 1000.0);
  auto code = api_->WaitContainer(*id, docker::WaitCondition::kNotRunning, nullptr);
  ASSERT_TRUE(code) << code.error().ToString();
  EXPECT_EQ(*code, 3);
  follower.join();
  EXPECT_TRUE(follow_status) << follow_status.error().ToString();
  EXPECT_TRUE(log.Has("stopping: bye")) << log.Dump();

  // Remove everything, and check it is gone.
  ASSERT_TRUE(api_->RemoveContainer(*id, false, true));
  ASSERT_TRUE(api_->RemoveNetwork(*net_id));
  auto gone = api_->InspectContainer(*id);
  ASSERT_FALSE(gone);
  EXPECT_EQ(gone.error().code(), ErrorCode::kNotFound);
  EXPECT_NE(gone.error().message().find("No such container"), std::string::npos);
  EXPECT_EQ(api_->InspectNetwork(*net_id).error().code(), ErrorCode::kNotFound);
  std::cout << "[figures] create-to-first-log-line " << create_to_first_line_ms
            << " ms; stop file PUT -> program's reaction line received " << line_latency_ms << " ms\n";
  RecordProperty("create_to_first_log_line_ms", std::to_string(create_to_first_line_ms));
}

TEST_F(DockerEndToEnd, ContainerOnTwoNetworksGetsBothFixedAddresses) {
  docker::NetworkSpec sim;
  sim.name = "sbx-" + run_id_ + "-sim";
  sim.labels = docker::SwarmboxLabels(run_id_, "t1", "sim");
  docker::NetworkSpec mesh = sim;
  mesh.name = "sbx-" + run_id_ + "-mesh";
  std::string sim_prefix, mesh_prefix;
  ASSERT_TRUE(testing::CreateFreeNetwork(*api_, sim, &sim_prefix));
  auto mesh_id = testing::CreateFreeNetwork(*api_, mesh, &mesh_prefix);
  ASSERT_TRUE(mesh_id) << mesh_id.error().ToString();
  ContainerSpec spec = ProbeContainer("drone_1", {"serve", "0"});
  spec.networks = {docker::EndpointSpec{sim.name, sim_prefix + "11", {}},
                   docker::EndpointSpec{mesh.name, mesh_prefix + "11", {}}};
  auto id = api_->CreateContainer(spec);
  ASSERT_TRUE(id) << id.error().ToString();
  ASSERT_TRUE(api_->StartContainer(*id));
  auto info = api_->InspectContainer(*id);
  ASSERT_TRUE(info) << info.error().ToString();
  EXPECT_EQ(info->network_ips.at(sim.name), sim_prefix + "11");
  EXPECT_EQ(info->network_ips.at(mesh.name), mesh_prefix + "11");
  // Name clash: a typed error with Docker's message.
  auto clash = api_->CreateContainer(spec);
  ASSERT_FALSE(clash);
  EXPECT_EQ(clash.error().code(), ErrorCode::kAlreadyExists);
  EXPECT_NE(clash.error().message().find("is already in use"), std::string::npos);
  // Pause/unpause/kill round.
  ASSERT_TRUE(api_->PauseContainer(*id));
  EXPECT_TRUE(api_->InspectContainer(*id)->state.paused);
  ASSERT_TRUE(api_->UnpauseContainer(*id));
  ASSERT_TRUE(api_->KillContainer(*id, "SIGKILL"));
  auto code = api_->WaitContainer(*id, docker::WaitCondition::kNotRunning, nullptr);
  ASSERT_TRUE(code) << code.error().ToString();
  EXPECT_EQ(*code, 137);
  auto again = api_->KillContainer(*id, "SIGKILL");
  ASSERT_FALSE(again);
  EXPECT_NE(again.error().message().find("is not running"), std::string::npos);
}

TEST_F(DockerEndToEnd, CancellingALogFollowReturnsPromptly) {
  ContainerSpec spec = ProbeContainer("idle", {"serve", "1"});
  auto id = api_->CreateContainer(spec);
  ASSERT_TRUE(id) << id.error().ToString();
  ASSERT_TRUE(api_->StartContainer(*id));
  docker::CancelToken cancel;
  testing::LineLog log;
  Status status = Ok{};
  std::thread follower([&] { status = api_->FollowLogs(*id, {}, log.Collector(), &cancel); });
  ASSERT_TRUE(log.WaitFor("warn 0", std::chrono::seconds(10))) << log.Dump();
  const auto t_cancel = Clock::now();
  cancel.Cancel();
  follower.join();
  const double cancel_ms = Ms(Clock::now() - t_cancel);
  ASSERT_FALSE(status);
  EXPECT_EQ(status.error().code(), ErrorCode::kCancelled);
  EXPECT_LT(cancel_ms, 200.0);
  std::cout << "[figures] log follow cancelled in " << cancel_ms << " ms\n";
}

TEST_F(DockerEndToEnd, TtyContainerLogsArriveRawAndEnvIsPassed) {
  ContainerSpec spec = ProbeContainer("tty", {"env", "SWARMBOX_TRIAL_SEED"});
  spec.tty = true;
  spec.env = {{"SWARMBOX_TRIAL_SEED", "42 and more"}};
  spec.resources.memory_bytes = 64 << 20;
  spec.resources.pids_limit = 32;
  auto id = api_->CreateContainer(spec);
  ASSERT_TRUE(id) << id.error().ToString();
  ASSERT_TRUE(api_->StartContainer(*id));
  auto code = api_->WaitContainer(*id, docker::WaitCondition::kNotRunning, nullptr);
  ASSERT_TRUE(code) << code.error().ToString();
  EXPECT_EQ(*code, 0);
  testing::LineLog log;
  docker::LogOptions options;
  options.follow = false;
  ASSERT_TRUE(api_->FollowLogs(*id, options, log.Collector(), nullptr));
  EXPECT_TRUE(log.Has("SWARMBOX_TRIAL_SEED=42 and more")) << log.Dump();  // no "\r" left over
}

TEST_F(DockerEndToEnd, EventsStreamReportsTheRunsContainersUntilCancelled) {
  docker::CancelToken cancel;
  std::mutex mu;
  std::vector<docker::Event> events;
  std::condition_variable cv;
  docker::EventFilter filter;
  filter.labels.equals = {{std::string(docker::kLabelRun), run_id_}};
  filter.types = {"container"};
  Status status = Ok{};
  std::thread watcher([&] {
    status = api_->StreamEvents(filter, [&](const docker::Event& e) {
      std::lock_guard<std::mutex> lock(mu);
      events.push_back(e);
      cv.notify_all();
    }, &cancel);
  });
  // The stream is open once the engine answers; give it a moment before acting.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  auto id = api_->CreateContainer(ProbeContainer("evented", {"exit", "5"}));
  ASSERT_TRUE(id) << id.error().ToString();
  ASSERT_TRUE(api_->StartContainer(*id));
  {
    std::unique_lock<std::mutex> lock(mu);
    const bool died = cv.wait_for(lock, std::chrono::seconds(10), [&] {
      for (const auto& e : events) {
        if (e.action == "die") return true;
      }
      return false;
    });
    ASSERT_TRUE(died);
    for (const auto& e : events) {
      EXPECT_EQ(e.attributes.at("swarmbox.run"), run_id_);
      if (e.action == "die") {
        EXPECT_EQ(e.attributes.at("exitCode"), "5");
      }
    }
    EXPECT_EQ(events.front().action, "create");
  }
  cancel.Cancel();
  watcher.join();
  ASSERT_FALSE(status);
  EXPECT_EQ(status.error().code(), ErrorCode::kCancelled);
}

TEST_F(DockerEndToEnd, LinesArriveLiveWithinMilliseconds) {
  // The container stamps each line with CLOCK_MONOTONIC (shared with the host: no time namespace);
  // the callback compares with steady_clock (CLOCK_MONOTONIC too): the true write-to-callback delay.
  auto id = api_->CreateContainer(ProbeContainer("stream", {"stream", "150"}));
  ASSERT_TRUE(id) << id.error().ToString();
  ASSERT_TRUE(api_->StartContainer(*id));
  const auto follow_start = Clock::now();
  std::vector<double> live_ms;
  std::mutex mu;
  Status s = api_->FollowLogs(*id, {}, [&](const docker::LogLine& line) {
    const auto received = Clock::now();
    const std::size_t at = line.text.find("mono_ns=");
    if (at == std::string::npos) return;
    const auto sent = Clock::time_point(std::chrono::nanoseconds(std::stoll(line.text.substr(at + 8))));
    if (sent < follow_start + std::chrono::milliseconds(100)) return;  // backlog, not live
    std::lock_guard<std::mutex> lock(mu);
    live_ms.push_back(Ms(received - sent));
  }, nullptr);
  ASSERT_TRUE(s) << s.error().ToString();
  ASSERT_GT(live_ms.size(), 50u);
  std::sort(live_ms.begin(), live_ms.end());
  const double p50 = live_ms[live_ms.size() / 2];
  const double p99 = live_ms[live_ms.size() * 99 / 100];
  EXPECT_LT(p99, 500.0);
  std::cout << "[figures] live log line latency over " << live_ms.size() << " lines: p50 " << p50
            << " ms, p99 " << p99 << " ms, max " << live_ms.back() << " ms\n";
}

TEST_F(DockerEndToEnd, OneClientServesConcurrentFollowersAndCalls) {
  // The runner follows every container's logs on its own thread through one client.
  constexpr int kContainers = 3;
  std::vector<std::string> ids;
  for (int i = 0; i < kContainers; ++i) {
    auto id = api_->CreateContainer(ProbeContainer("c" + std::to_string(i), {"serve", "20"}));
    ASSERT_TRUE(id) << id.error().ToString();
    ids.push_back(*id);
  }
  std::vector<testing::LineLog> logs(kContainers);
  std::vector<Status> results(kContainers, Status(Ok{}));
  std::vector<std::thread> followers;
  for (int i = 0; i < kContainers; ++i) {
    ASSERT_TRUE(api_->StartContainer(ids[static_cast<std::size_t>(i)]));
    followers.emplace_back([&, i] {
      const auto k = static_cast<std::size_t>(i);
      results[k] = api_->FollowLogs(ids[k], {}, logs[k].Collector(), nullptr);
    });
  }
  docker::LabelSelector run;
  run.equals = {{std::string(docker::kLabelRun), run_id_}};
  for (int round = 0; round < 10; ++round) {  // ordinary calls meanwhile, on this thread
    auto list = api_->ListContainers(run, true);
    ASSERT_TRUE(list) << list.error().ToString();
    EXPECT_EQ(list->size(), static_cast<std::size_t>(kContainers));
  }
  for (int i = 0; i < kContainers; ++i) {
    const auto k = static_cast<std::size_t>(i);
    ASSERT_TRUE(logs[k].WaitFor("tick 19", std::chrono::seconds(20))) << logs[k].Dump();
    ASSERT_TRUE(logs[k].WaitFor("warn 19", std::chrono::seconds(20))) << logs[k].Dump();
    docker::TarWriter stop;
    ASSERT_TRUE(stop.AddFile("stop", "done\n"));
    ASSERT_TRUE(api_->PutArchive(ids[k], "/tmp", *stop.Finish()));
  }
  for (auto& t : followers) t.join();
  for (int i = 0; i < kContainers; ++i) {
    const auto k = static_cast<std::size_t>(i);
    EXPECT_TRUE(results[k]) << results[k].error().ToString();
    EXPECT_TRUE(logs[k].Has("stopping: done")) << logs[k].Dump();
    EXPECT_EQ(logs[k].lines().size(), 42u) << logs[k].Dump();  // ready + 20 + 20 + stopping
  }
}

TEST_F(DockerEndToEnd, RemoveLabelledLeavesNothingLabelledBehind) {
  // Things of this run: two networks, a running, a created and an exited container.
  docker::NetworkSpec net;
  net.name = "sbx-" + run_id_ + "-n1";
  net.labels = docker::SwarmboxLabels(run_id_, "t1", "sim");
  std::string prefix;
  ASSERT_TRUE(testing::CreateFreeNetwork(*api_, net, &prefix));
  docker::NetworkSpec net2 = net;
  net2.name = "sbx-" + run_id_ + "-n2";
  std::string prefix2;
  ASSERT_TRUE(testing::CreateFreeNetwork(*api_, net2, &prefix2));
  ContainerSpec running = ProbeContainer("running", {"serve", "0"});
  running.networks = {docker::EndpointSpec{net.name, prefix + "20", {}}};
  auto running_id = api_->CreateContainer(running);
  ASSERT_TRUE(running_id) << running_id.error().ToString();
  ASSERT_TRUE(api_->StartContainer(*running_id));
  ContainerSpec created = ProbeContainer("created", {"serve", "0"});
  created.networks = {docker::EndpointSpec{net2.name, prefix2 + "21", {}}};
  ASSERT_TRUE(api_->CreateContainer(created));
  auto exited_id = api_->CreateContainer(ProbeContainer("exited", {"exit", "0"}));
  ASSERT_TRUE(exited_id);
  ASSERT_TRUE(api_->StartContainer(*exited_id));
  ASSERT_TRUE(api_->WaitContainer(*exited_id, docker::WaitCondition::kNotRunning, nullptr));

  // Something of another run must survive.
  const std::string other_run = run_id_ + "-other";
  ContainerSpec other = ProbeContainer("other", {"exit", "0"});
  other.name += "-other";
  other.labels = docker::SwarmboxLabels(other_run, "t1", "other");
  auto other_id = api_->CreateContainer(other);
  ASSERT_TRUE(other_id) << other_id.error().ToString();

  LabelSelector run;
  run.equals = {{std::string(docker::kLabelRun), run_id_}};
  auto report = docker::RemoveLabelled(*api_, run, /*include_images=*/false);
  ASSERT_TRUE(report) << report.error().ToString();
  EXPECT_TRUE(report->failures.empty()) << report->failures.front().ToString();
  EXPECT_EQ(report->containers.size(), 3u);
  EXPECT_EQ(report->networks.size(), 2u);

  auto containers = api_->ListContainers(run, true);
  ASSERT_TRUE(containers);
  EXPECT_TRUE(containers->empty());
  auto networks = api_->ListNetworks(run);
  ASSERT_TRUE(networks);
  EXPECT_TRUE(networks->empty());
  EXPECT_TRUE(api_->InspectContainer(*other_id)) << "another run's container was removed";

  LabelSelector other_sel;
  other_sel.equals = {{std::string(docker::kLabelRun), other_run}};
  ASSERT_TRUE(docker::RemoveLabelled(*api_, other_sel, false));
  EXPECT_EQ(api_->InspectContainer(*other_id).error().code(), ErrorCode::kNotFound);

  auto refused = docker::RemoveLabelled(*api_, LabelSelector{}, false);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message().find("empty label selector"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox
