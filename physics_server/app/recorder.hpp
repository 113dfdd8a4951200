// Recorder: the physics server's side of the recording (ARCHITECTURE.md "Recordings", the
// channel table of ARCHITECTURE.md "Recordings"): builds every channel's JSON and writes it to the
// record::Sinks it was given (McapWriter for --record PATH, LiveServer for --view ADDR:PORT).
//
//   Recorder rec(sinks, {"scout_1", "scout_2"}, world_config, RecordOptions{});
//   rec.Start();                          // /world at t=0
//   ... every lockstep step: rec.OnStep(world)   (true poses at rate_hz, the queued telemetry
//   and log lines); rec.OnCamera(i, image) for each rendered frame (camera_hz, scaled, JPEG);
//   bus thread: rec.OnTelemetry(t); any thread printing the server's log: rec.OnLogLine(line)
//   rec.Finish();                         // everything queued is written
//
// Timing: true poses are written at rate_hz of simulated time, agents' telemetry as it comes
// (stamped with the agent's simulated time), camera frames at camera_hz. Nothing here feeds back
// into the simulation. Writing happens on a writer thread with a bounded queue (queue_bytes): the
// lockstep pays for building the JSON and JPEG-encoding, not for compression or file I/O, unless
// the writer falls that far behind (then the step waits: nothing is dropped).
// Thread-safety: OnTelemetry and OnLogLine from any thread; the rest from the server's thread.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <unordered_map>
#include <vector>

#include "recorder_json.hpp"
#include "sim_server.hpp"
#include "swarmbox/bus/messages.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/physics/camera_image.hpp"
#include "swarmbox/physics/world.hpp"
#include "swarmbox/record/sink.hpp"

namespace swarmbox::physics {

struct RecordOptions {
  double rate_hz = 10.0;        // true poses per simulated second (> 0)
  double camera_hz = 1.0;       // camera frames per simulated second per drone (0 = none)
  double camera_scale = 0.5;    // (0, 1]: frames are resized by it before encoding
  int jpeg_quality = 75;        // [1, 100]
  std::size_t queue_bytes = 64u << 20;  // the writer thread's queue bound
  std::string node = "physics";         // the server's node name (its log lines)
};

// kInvalidArgument naming the field when an option is out of range.
Status ValidateRecordOptions(const RecordOptions& options);

class Recorder final : public StepObserver {
 public:
  // Adds every channel to every sink (kInvalidArgument: a bad option; a sink's error otherwise).
  // The sinks must outlive the recorder.
  static Result<std::unique_ptr<Recorder>> Create(std::vector<record::Sink*> sinks, std::vector<std::string> drones,
                                                  WorldConfig world, RecordOptions options);
  ~Recorder() override;  // Finish() if not called

  void Start();                  // /world at t = 0
  void OnStep(const World& world) override;
  // Written when due for this drone (camera_hz), as the frame's simulated time.
  void OnCamera(std::size_t drone, const CameraImage& image) override;
  void OnTelemetry(const bus::Telemetry& telemetry);  // any thread: queued for the next OnStep
  void OnLogLine(std::string_view line);              // any thread: queued for the next OnStep
  // Writes what is queued, stops the writer thread: the sinks have every message. The first
  // sink error seen (later ones are counted).
  Status Finish();

  // Written so far (for tests and the benchmark).
  std::uint64_t messages() const { return messages_; }
  std::uint64_t bytes() const { return bytes_; }

  // Without the world: the true poses of this time (tests; OnStep builds them from the World).
  void WriteTruth(std::uint64_t t_ns, std::span<const TruthPose> poses);
  // The queued telemetry and log lines (OnStep does it every step).
  void Drain();

 private:
  struct DroneChannels {
    int truth, estimate, setpoint, flocking, raft, status, camera;
    std::int64_t next_camera_ns = 0;
  };
  struct Pending {
    int channel;
    std::uint64_t t_ns;
    std::string json;
  };
  Recorder(std::vector<record::Sink*> sinks, std::vector<std::string> drones, WorldConfig world, RecordOptions options);
  Status AddChannels();
  int Add(std::string topic);
  void Write(int channel, std::uint64_t t_ns, std::string json);
  void WriteTelemetry(const bus::Telemetry& t);
  void WriteLogLine(const std::string& line);
  void WriterLoop();

  std::vector<record::Sink*> sinks_;
  std::vector<std::string> drones_;
  std::unordered_map<std::string, std::size_t> drone_index_;
  WorldConfig world_;
  RecordOptions options_;
  std::int64_t period_ns_ = 0;
  std::int64_t next_truth_ns_ = 0;
  std::int64_t camera_period_ns_ = 0;
  std::vector<std::string> topics_;                    // by channel index
  std::vector<std::vector<record::ChannelId>> ids_;    // [sink][channel index]
  std::vector<DroneChannels> per_drone_;
  int world_ch_ = -1, tf_ch_ = -1, flocking_scene_ch_ = -1, links_ch_ = -1, sectors_ch_ = -1, detections_ch_ = -1,
      log_ch_ = -1;
  std::vector<TruthPose> poses_;
  std::vector<bus::TelemetrySector> last_sectors_;

  std::mutex in_mu_;  // the queues of OnTelemetry / OnLogLine
  std::vector<bus::Telemetry> telemetry_in_;
  std::vector<std::string> lines_in_;
  std::vector<bus::Telemetry> telemetry_scratch_;
  std::vector<std::string> lines_scratch_;

  std::mutex mu_;  // the writer's queue
  std::condition_variable cv_;
  std::deque<Pending> queue_;
  std::size_t queued_bytes_ = 0;
  bool stopping_ = false;
  bool finished_ = false;
  std::optional<Error> error_;
  std::uint64_t errors_ = 0;
  std::uint64_t messages_ = 0;
  std::uint64_t bytes_ = 0;
  std::thread writer_;
};

}  // namespace swarmbox::physics
