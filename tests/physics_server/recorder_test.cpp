// The recording's JSON builders and the Recorder with a fake sink: channels, timestamps, the
// contract's fields (ARCHITECTURE.md "Recordings"), rates, and that NaN becomes null.
#include "recorder.hpp"

#include <gtest/gtest.h>

#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "recorder_json.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/record/mcap.hpp"
#include "swarmbox/record/foxglove_schemas.hpp"

namespace swarmbox::physics {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

yaml::Node Json(const std::string& text) {
  auto n = yaml::Parse(text);
  EXPECT_TRUE(n) << text;
  return n ? *n : yaml::Node();
}
double D(const yaml::Node& n) { return *n.AsDouble(); }
std::string S(const yaml::Node& n) { return *n.AsString(); }
const yaml::Node& At(const yaml::Node& n, std::string_view key) {
  const yaml::Node* f = n.Find(key);
  EXPECT_NE(f, nullptr) << key;
  static const yaml::Node kNull;
  return f != nullptr ? *f : kNull;
}

class FakeSink final : public record::Sink {
 public:
  struct Message {
    std::string topic;
    std::uint64_t t_ns;
    std::string json;
  };
  Result<record::ChannelId> AddChannel(const record::ChannelSpec& spec) override {
    specs.push_back(spec);
    return static_cast<record::ChannelId>(specs.size() - 1 + 100);  // not the recorder's index
  }
  Status Write(record::ChannelId channel, std::uint64_t t_ns, std::string_view json) override {
    messages.push_back({specs.at(channel - 100).topic, t_ns, std::string(json)});
    return Ok{};
  }
  std::vector<Message> On(std::string_view topic) const {
    std::vector<Message> out;
    for (const Message& m : messages) {
      if (m.topic == topic) out.push_back(m);
    }
    return out;
  }
  std::vector<record::ChannelSpec> specs;
  std::vector<Message> messages;
};

WorldConfig SmallWorld() {
  WorldConfig w;
  w.size_x_m = 100;
  w.size_y_m = 60;
  ObstacleBox box;
  box.id = "shed";
  box.center_m = {10, 5, 2};
  box.size_m = {4, 6, 4};
  w.obstacles.push_back(box);
  w.victims.push_back({"v1", 20, -10, 0.5});
  return w;
}

bus::Telemetry SomeTelemetry(std::string drone, std::int64_t t_ns) {
  bus::Telemetry t;
  t.drone = std::move(drone);
  t.sim_time_ns = t_ns;
  t.position_enu_m = {1, 2, 30};
  t.velocity_enu_m_s = {0.5, 0, 0};
  t.flight_mode = "trajectory";
  t.setpoint_position_enu_m = {kNaN, kNaN, kNaN};
  t.setpoint_velocity_enu_m_s = {3, 4, 0};
  t.setpoint_yaw_rad = kNaN;
  t.flock_separation = {1, 0, 0};
  t.flock_alignment = {0, 1, 0};
  t.flock_cohesion = {0, 0, 0};
  t.flock_sum = {1, 1, 0};
  t.raft_role = "pre_candidate";
  t.raft_term = 4;
  t.raft_leader = "";
  t.raft_commit_index = 17;
  t.battery_fraction = 0.8;
  t.mission_stage = "scout/searching";
  t.armed = true;
  t.landed = false;
  t.links = {{"scout_2", 0.25, 12.5}, {"scout_3", 1.0, kNaN}};
  t.sectors = {{"scout_1", {0, 0, 10, 0, 10, 10, 0, 10}}};
  bus::Detection d;
  d.from = t.drone;
  d.sim_time_ns = t_ns - 40'000'000;
  d.confidence = 0.9;
  d.position_enu_m = {20, -10, 0};
  t.detections = {d};
  t.events = {{t.drone, t_ns - 1'000'000, "link_lost", {{"peer", "scout_2"}}}};
  return t;
}

TEST(RecorderJson, TimestampsAreSimulatedSecondsAndNanoseconds) {
  TruthPose p{"scout_1", {1, 2, 3}, {4, 5, 6}, {1, 0, 0, 0}};
  const yaml::Node n = Json(TruthJson(12'345'000'000, p));
  EXPECT_EQ(D(At(At(n, "timestamp"), "sec")), 12);
  EXPECT_EQ(D(At(At(n, "timestamp"), "nsec")), 345'000'000);
  EXPECT_EQ(S(At(n, "drone")), "scout_1");
  ASSERT_EQ(At(n, "position").items().size(), 3u);
  EXPECT_EQ(D(At(n, "position").items()[2]), 3);
  EXPECT_EQ(D(At(At(n, "orientation"), "w")), 1);
}

TEST(RecorderJson, WorldSceneHasGroundObstaclesAndVictims) {
  const yaml::Node n = Json(WorldSceneJson(0, SmallWorld()));
  const auto& entities = At(n, "entities").items();
  ASSERT_EQ(entities.size(), 3u);
  EXPECT_EQ(S(At(entities[0], "id")), "ground");
  EXPECT_EQ(D(At(At(At(entities[0], "cubes").items()[0], "size"), "x")), 100);
  EXPECT_EQ(D(At(At(At(entities[0], "cubes").items()[0], "size"), "y")), 60);
  EXPECT_EQ(S(At(At(entities[1], "metadata").items()[0], "value")), "obstacle");
  EXPECT_EQ(S(At(At(entities[2], "metadata").items()[0], "value")), "victim");
  EXPECT_EQ(D(At(At(At(At(entities[2], "cubes").items()[0], "pose"), "position"), "x")), 20);
}

TEST(RecorderJson, UnsetSetpointAxesAreNull) {
  const yaml::Node n = Json(SetpointJson(SomeTelemetry("scout_1", 1'000'000'000)));
  EXPECT_TRUE(At(n, "position").items()[0].is_null());
  EXPECT_EQ(D(At(n, "velocity").items()[1]), 4);
  EXPECT_TRUE(At(n, "yaw").is_null());
  EXPECT_EQ(S(At(n, "flight_mode")), "trajectory");
}

TEST(RecorderJson, RaftRoleUsesTheSchemasNames) {
  const yaml::Node n = Json(RaftJson(SomeTelemetry("scout_1", 0)));
  EXPECT_EQ(S(At(n, "role")), "candidate");  // pre_candidate is a candidate to the viewer
  EXPECT_EQ(D(At(n, "term")), 4);
  EXPECT_EQ(D(At(n, "commit_index")), 17);
}

TEST(RecorderJson, LinksNameBothEndsAndSectorsArePolygons) {
  const bus::Telemetry t = SomeTelemetry("scout_1", 0);
  const yaml::Node links = Json(LinksJson(t));
  ASSERT_EQ(At(links, "links").items().size(), 2u);
  EXPECT_EQ(S(At(At(links, "links").items()[0], "from")), "scout_1");
  EXPECT_EQ(S(At(At(links, "links").items()[0], "to")), "scout_2");
  EXPECT_EQ(D(At(At(links, "links").items()[0], "rtt_ms")), 12.5);
  EXPECT_TRUE(At(At(links, "links").items()[1], "rtt_ms").is_null());
  const yaml::Node sectors = Json(SectorsJson(t));
  const auto& polygon = At(At(sectors, "sectors").items()[0], "polygon").items();
  ASSERT_EQ(polygon.size(), 4u);
  EXPECT_EQ(D(polygon[2].items()[0]), 10);
  EXPECT_EQ(D(polygon[2].items()[1]), 10);
}

TEST(RecorderJson, FlockingSceneHasAnArrowPerNonZeroTerm) {
  const yaml::Node n = Json(FlockingSceneJson(SomeTelemetry("scout_1", 0)));
  const yaml::Node& entity = At(n, "entities").items()[0];
  EXPECT_EQ(S(At(entity, "id")), "flocking/scout_1");
  EXPECT_EQ(At(entity, "arrows").items().size(), 3u);  // cohesion is zero: no arrow
}

TEST(RecorderJson, LogLevelsFollowTheEventName) {
  EXPECT_EQ(LogLevelOf("hover"), record::kLogInfo);
  EXPECT_EQ(LogLevelOf("drone_lost"), record::kLogWarning);
  EXPECT_EQ(LogLevelOf("world_command_rejected"), record::kLogWarning);
  EXPECT_EQ(LogLevelOf("error"), record::kLogError);
  EXPECT_EQ(LogLevelOf("bus_error"), record::kLogError);
  const yaml::Node n = Json(EventLogJson({"scout_1", 2'500'000'000, "leader_elected", {{"term", "3"}}}));
  EXPECT_EQ(S(At(n, "message")), "t=2.500 node=scout_1 event=leader_elected term=3");
  EXPECT_EQ(S(At(n, "name")), "scout_1");
  EXPECT_EQ(D(At(n, "level")), record::kLogInfo);
}

TEST(RecorderJson, Base64AsRfc4648) {
  auto b = [](std::string s) { return Base64({reinterpret_cast<const std::uint8_t*>(s.data()), s.size()}); };
  EXPECT_EQ(b(""), "");
  EXPECT_EQ(b("f"), "Zg==");
  EXPECT_EQ(b("fo"), "Zm8=");
  EXPECT_EQ(b("foo"), "Zm9v");
  EXPECT_EQ(b("foobar"), "Zm9vYmFy");
}

TEST(Recorder, AddsTheContractsChannelsToEverySink) {
  FakeSink a, b;
  auto rec = Recorder::Create({&a, &b}, {"scout_1", "lifter"}, SmallWorld(), RecordOptions{});
  ASSERT_TRUE(rec) << rec.error().ToString();
  std::map<std::string, std::string> schema_of;
  for (const auto& s : a.specs) schema_of[s.topic] = s.schema_name;
  EXPECT_EQ(schema_of["/world"], "foxglove.SceneUpdate");
  EXPECT_EQ(schema_of["/tf"], "foxglove.FrameTransforms");
  EXPECT_EQ(schema_of["/drones/lifter/truth"], "swarmbox.DroneTruth");
  EXPECT_EQ(schema_of["/drones/lifter/estimate"], "foxglove.PoseInFrame");
  EXPECT_EQ(schema_of["/drones/scout_1/setpoint"], "swarmbox.Setpoint");
  EXPECT_EQ(schema_of["/drones/scout_1/flocking"], "swarmbox.Flocking");
  EXPECT_EQ(schema_of["/drones/scout_1/raft"], "swarmbox.RaftState");
  EXPECT_EQ(schema_of["/drones/scout_1/status"], "swarmbox.AgentStatus");
  EXPECT_EQ(schema_of["/drones/scout_1/camera"], "foxglove.CompressedImage");
  EXPECT_EQ(schema_of["/flocking"], "foxglove.SceneUpdate");
  EXPECT_EQ(schema_of["/radio/links"], "swarmbox.Links");
  EXPECT_EQ(schema_of["/mission/sectors"], "swarmbox.Sectors");
  EXPECT_EQ(schema_of["/detections"], "swarmbox.Detection");
  EXPECT_EQ(schema_of["/log"], "foxglove.Log");
  EXPECT_EQ(a.specs.size(), b.specs.size());
  EXPECT_FALSE(a.specs.front().schema.empty());
}

TEST(Recorder, WritesTelemetryAndLogLinesAtTheirSimulatedTimes) {
  FakeSink sink;
  auto rec = Recorder::Create({&sink}, {"scout_1", "scout_2"}, SmallWorld(), RecordOptions{});
  ASSERT_TRUE(rec);
  (*rec)->Start();
  (*rec)->OnTelemetry(SomeTelemetry("scout_1", 2'000'000'000));
  (*rec)->OnTelemetry(SomeTelemetry("scout_1", 2'100'000'000));  // the same plan: sectors once
  (*rec)->OnTelemetry(SomeTelemetry("intruder", 2'100'000'000));  // not in the trial: ignored
  (*rec)->OnLogLine("t=1.250 node=physics event=drone_lost drone=scout_2");
  ASSERT_TRUE((*rec)->Finish());
  ASSERT_EQ(sink.On("/world").size(), 1u);
  EXPECT_EQ(sink.On("/world")[0].t_ns, 0u);
  ASSERT_EQ(sink.On("/drones/scout_1/estimate").size(), 2u);
  EXPECT_EQ(sink.On("/drones/scout_1/estimate")[0].t_ns, 2'000'000'000u);
  EXPECT_EQ(sink.On("/drones/scout_1/flocking").size(), 2u);
  EXPECT_EQ(sink.On("/flocking").size(), 2u);
  EXPECT_EQ(sink.On("/drones/scout_1/raft").size(), 2u);
  EXPECT_EQ(sink.On("/drones/scout_1/status").size(), 2u);
  EXPECT_EQ(sink.On("/radio/links").size(), 2u);
  EXPECT_EQ(sink.On("/mission/sectors").size(), 1u);
  ASSERT_EQ(sink.On("/detections").size(), 2u);
  EXPECT_EQ(sink.On("/detections")[0].t_ns, 1'960'000'000u);
  EXPECT_TRUE(sink.On("/drones/scout_2/estimate").empty());
  // The server's line and the agent's two events.
  const auto logs = sink.On("/log");
  ASSERT_EQ(logs.size(), 3u);
  EXPECT_EQ(logs[0].t_ns, 1'250'000'000u);
  EXPECT_EQ(S(At(Json(logs[0].json), "name")), "physics");
  EXPECT_EQ(D(At(Json(logs[0].json), "level")), record::kLogWarning);
  EXPECT_EQ(logs[1].t_ns, 1'999'000'000u);
  EXPECT_EQ((*rec)->messages(), sink.messages.size());
}

TEST(Recorder, TruthGoesToTfAndEachDrone) {
  FakeSink sink;
  auto rec = Recorder::Create({&sink}, {"scout_1", "scout_2"}, SmallWorld(), RecordOptions{});
  ASSERT_TRUE(rec);
  std::vector<TruthPose> poses = {{"scout_1", {1, 2, 3}, {}, {1, 0, 0, 0}}, {"scout_2", {4, 5, 6}, {}, {1, 0, 0, 0}}};
  (*rec)->WriteTruth(100'000'000, poses);
  ASSERT_TRUE((*rec)->Finish());
  ASSERT_EQ(sink.On("/tf").size(), 1u);
  const yaml::Node tf = Json(sink.On("/tf")[0].json);
  ASSERT_EQ(At(tf, "transforms").items().size(), 2u);
  EXPECT_EQ(S(At(At(tf, "transforms").items()[1], "child_frame_id")), "scout_2");
  EXPECT_EQ(S(At(At(tf, "transforms").items()[1], "parent_frame_id")), "world");
  EXPECT_EQ(sink.On("/drones/scout_2/truth").size(), 1u);
}

TEST(Recorder, CameraFramesAreSubsampledScaledAndJpeg) {
  FakeSink sink;
  RecordOptions o;
  o.camera_hz = 1.0;
  o.camera_scale = 0.5;
  auto rec = Recorder::Create({&sink}, {"scout_1"}, SmallWorld(), o);
  ASSERT_TRUE(rec);
  CameraImage img;
  img.width_px = 64;
  img.height_px = 48;
  img.bgr.assign(64 * 48 * 3, 128);
  for (std::int64_t t = 0; t < 3'000'000'000; t += 200'000'000) {  // 5 Hz for 3 s
    img.time_ns = t;
    (*rec)->OnCamera(0, img);
  }
  ASSERT_TRUE((*rec)->Finish());
  const auto frames = sink.On("/drones/scout_1/camera");
  ASSERT_EQ(frames.size(), 3u);  // t = 0, 1, 2 s
  EXPECT_EQ(frames[1].t_ns, 1'000'000'000u);
  const yaml::Node n = Json(frames[0].json);
  EXPECT_EQ(S(At(n, "format")), "jpeg");
  EXPECT_EQ(S(At(n, "data")).rfind("/9j/", 0), 0u);  // base64 of the JPEG SOI marker FF D8 FF
}

// What recording costs (BENCHMARKS.md "Recording"): one simulated minute of 4 drones at the
// defaults (poses and telemetry at 10 Hz, a 320x240 camera frame per drone per second: a textured
// gradient, JPEG 75 at half size), through the real McapWriter (zstd) on a writer thread. Prints
// the CPU time and the bytes per drone-minute; checks the file reads back with every message.
TEST(Recorder, CostOfAFourDroneMinute) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("recorder-cost-" + std::to_string(::getpid()) + ".mcap")).string();
  auto cpu_s = [] {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
  };
  const std::vector<std::string> drones = {"scout_1", "scout_2", "scout_3", "lifter"};
  CameraImage img;
  img.width_px = 320;
  img.height_px = 240;
  img.bgr.resize(320 * 240 * 3);
  for (int y = 0; y < 240; ++y) {
    for (int x = 0; x < 320; ++x) {
      const std::size_t i = (static_cast<std::size_t>(y) * 320 + static_cast<std::size_t>(x)) * 3;
      const int grain = ((x * 7919 + y * 104729) >> 3) % 23;  // ground texture
      img.bgr[i] = static_cast<std::uint8_t>(60 + x / 8 + grain);
      img.bgr[i + 1] = static_cast<std::uint8_t>(110 + y / 6 + grain);
      img.bgr[i + 2] = static_cast<std::uint8_t>(70 + grain);
    }
  }
  const double cpu0 = cpu_s();
  std::uint64_t written = 0;
  {
    auto writer = record::McapWriter::Create(path);
    ASSERT_TRUE(writer) << writer.error().ToString();
    auto rec = Recorder::Create({writer->get()}, drones, SmallWorld(), RecordOptions{});
    ASSERT_TRUE(rec);
    (*rec)->Start();
    std::vector<TruthPose> poses(drones.size());
    for (std::int64_t step = 0; step <= 15'000; ++step) {  // 60 s of 4 ms lockstep steps
      const std::int64_t t_ns = step * 4'000'000;
      if (t_ns % 100'000'000 == 0) {
        for (std::size_t d = 0; d < drones.size(); ++d) {
          poses[d] = {drones[d], {static_cast<double>(step) * 0.01, static_cast<double>(d), 30}, {2.5, 0, 0}, {1, 0, 0, 0}};
          bus::Telemetry t = SomeTelemetry(drones[d], t_ns);
          t.sectors.clear();
          t.detections.clear();
          if (step % 500 != 0) t.links.clear();  // the probe reports every 2 s
          if (step % 250 != 0) t.events.clear();  // an event a second per drone
          (*rec)->OnTelemetry(t);
        }
        (*rec)->WriteTruth(static_cast<std::uint64_t>(t_ns), poses);
        (*rec)->Drain();
      }
      if (t_ns % 200'000'000 == 0) {  // the 5 Hz camera, recorded at 1 Hz
        img.time_ns = t_ns;
        for (std::size_t d = 0; d < drones.size(); ++d) (*rec)->OnCamera(d, img);
      }
    }
    ASSERT_TRUE((*rec)->Finish());
    written = (*rec)->messages();
    ASSERT_TRUE((*writer)->Close());
  }
  const double cpu = cpu_s() - cpu0;
  const auto bytes = std::filesystem::file_size(path);
  auto reader = record::McapReader::Open(path);
  ASSERT_TRUE(reader) << reader.error().ToString();
  EXPECT_EQ(reader->message_count(), written);
  EXPECT_EQ(reader->end_ns(), 60'000'000'000u);
  std::cout << "[recording cost] 4 drones x 60 simulated s: " << written << " messages, " << bytes << " bytes ("
            << bytes / 4 << " bytes per drone-minute), CPU " << cpu << " s (" << cpu / 4 * 1000
            << " ms per drone-minute, recorder + writer thread)" << std::endl;
  std::filesystem::remove(path);
}

TEST(Recorder, RejectsBadOptionsNamingTheField) {
  FakeSink sink;
  RecordOptions o;
  o.jpeg_quality = 0;
  auto rec = Recorder::Create({&sink}, {"scout_1"}, SmallWorld(), o);
  ASSERT_FALSE(rec);
  EXPECT_NE(rec.error().message().find("jpeg_quality"), std::string::npos);
  o = RecordOptions{};
  o.camera_scale = 1.5;
  EXPECT_NE(ValidateRecordOptions(o).error().message().find("camera_scale"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::physics
