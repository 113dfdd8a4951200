// SimServer: the swarmbox-physics main loop, written against two small interfaces so it runs the
// same on the DDS bus (BusTransport) and in tests (fakes):
//   SimTransport  publishes sensor samples, camera images and the clock; delivers actuator and
//                 world commands.
//   WallClock     monotonic wall time and sleeping (pacing, lockstep timeouts).
//
// Per control step k (t_k = k * control period), the simulated time line of everything an agent
// hears:
//   1. for each drone in order: its camera frame if due, FIRST, then its stereo pair if due
//      (StereoCapture: airframes with stereo enabled, a fixed step schedule; not for a lost drone),
//      then its sample k with camera_frame / stereo_frame = true when a frame / pair went out
//      (lost drones get samples too, so they can rejoin; drones out of the trial by a plan's
//      drone_out get nothing);
//   2. wait until every live drone has answered step k (Lockstep); drones silent past the
//      timeout are marked lost (motors off, event=drone_lost) and the step goes on;
//   3. apply the answers' `world` commands (drone order, then seq), then those of the
//      sim/world_command topic (arrival order), track each drone's raft_leader flag, then carry out
//      the radio plan's entries due at t_k (drone_out/back, world commands, raft_leader targets);
//   4. World::Step() to t_{k+1}.
// With a radio profile (--radio-model channel) the server hosts the simulated radio channel
// (swarmbox::channel::Channel): at the start of step k it takes the channel's deliveries up to
// t_k into each drone's sample (radio_in, in delivery order), then gives it the drones' true
// positions at t_k; after the answers' world commands it hands each answer's radio_out frames to
// the channel with send time t_k (drone order, then seq), before the plan's entries of t_k.
// While waiting, every drone's sample is published again every 200 ms (agents that join late, a
// lost message, and a keepalive for the drones that answered, so a long wait does not look like a
// stalled server to them; an unanswered drone's camera frame and stereo pair go again first). Duplicate and
// stale commands are dropped (Lockstep).
// A camera is due by its airframe's trigger (CameraTrigger: rate_hz, or distance-triggered).
// While the first step waits, every second `event=joining joined=.. expected=.. missing=..` and the
// same on sim/status (joining.hpp); `event=joined` once it completes.
// Then World::Step(), truth.csv, pacing to the real-time factor. Events are printed as logfmt
// lines on `events_out`, and every `clock_every_s` simulated seconds a progress line
//   t=10.000 node=physics event=clock rtf=0.98 steps=2500 late=3 lost=0
// (ClockProgress below), so simulated time is seen to advance between events.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "camera_trigger.hpp"
#include "joining.hpp"
#include "radio_plan.hpp"
#include "stereo_capture.hpp"
#include "swarmbox/bus/messages.hpp"
#include "swarmbox/channel/channel.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/physics/camera_image.hpp"
#include "swarmbox/physics/lockstep.hpp"
#include "swarmbox/physics/sensor_sample.hpp"
#include "swarmbox/physics/thermal_renderer.hpp"
#include "swarmbox/physics/truth_log.hpp"
#include "swarmbox/physics/world.hpp"

namespace swarmbox::physics {

// The bus contract of WorldCommand (bus/messages.hpp): gps_dropout {duration_s},
// gps_degrade {duration_s, h_acc_m, v_acc_m}, imu_bias_jump {ax, ay, az, gx, gy, gz},
// wind_gust {vx, vy, vz, duration_s}, payload_attach {[mass_kg], ignored: the airframe's payload},
// payload_release {}. Anything else is rejected with event=world_command_rejected.
struct WorldCommandInput {
  std::string target;
  std::string command;
  std::vector<double> args;
  std::uint64_t seq = 0;   // per sender; orders one answer's commands
};

// One agent's answer to a sample (bus ActuatorCommand).
struct ActuatorInput {
  std::string drone;
  std::uint64_t step = 0;
  bool armed = false;
  std::vector<double> throttle;
  bool raft_leader = false;                  // this agent's Raft node leads
  std::vector<WorldCommandInput> world;      // applied once every live drone answered the step
  std::vector<bus::RadioFrame> radio_out;    // radio.model channel: sent at this step's time
};

// What a sensor sample carries beside the sensors.
struct SampleExtras {
  bool camera_frame = false;                 // this step's camera frame was published before it
  std::span<const bus::RadioFrame> radio_in; // deliveries in (t_{k-1}, t_k], in delivery order
  bool stereo_frame = false;                 // this step's stereo pair was published before it
};

class SimTransport {
 public:
  virtual ~SimTransport() = default;
  virtual Status PublishSample(std::size_t drone, const std::string& name, const SensorSample& sample,
                               const SampleExtras& extras) = 0;
  virtual Status PublishCamera(std::size_t drone, const std::string& name, std::uint64_t step, const CameraImage& image) = 0;
  // A thermal frame (airframe `thermal:`), taken with the camera frame and published just before
  // it on the same topic (bus/messages.hpp, CameraImage "mono16"); only for drones whose airframe
  // has a thermal camera.
  virtual Status PublishThermal(std::size_t drone, const std::string& name, std::uint64_t step,
                                const ThermalImage& image) = 0;
  // A stereo pair, already in the bus layout (bus/messages.hpp, CameraImage); only for drones whose
  // airframe has stereo enabled.
  virtual Status PublishStereo(std::size_t drone, const bus::CameraImage& pair) = 0;
  virtual Status PublishClock(std::uint64_t step, std::int64_t sim_time_ns, std::int64_t period_ns, double rtf) = 0;
  // The start's progress (joining.hpp), every second while the first step waits and once when it
  // completes (`done`): on the bus, sim/status, the agents' sign of a live server before their
  // first sample.
  virtual Status PublishStatus(const JoiningStatus& status, bool done) = 0;
  // Appends the actuator commands that arrived, waiting until `awaited` (>= 1: the live drones
  // that have not answered the step) are queued or wall time `deadline_ns` (WallClock time)
  // passes. Waking once per step rather than once per answer is what keeps 100 answers a step
  // from costing 100 thread wake-ups; a duplicate or stale command only ends the wait early.
  virtual void WaitActuators(std::int64_t deadline_ns, std::size_t awaited, std::vector<ActuatorInput>* out) = 0;
  virtual void TakeWorldCommands(std::vector<WorldCommandInput>* out) = 0;
};

class WallClock {
 public:
  virtual ~WallClock() = default;
  virtual std::int64_t NowNs() = 0;
  virtual void SleepUntilNs(std::int64_t t_ns) = 0;
};

// std::chrono::steady_clock.
class SteadyWallClock final : public WallClock {
 public:
  std::int64_t NowNs() override;
  void SleepUntilNs(std::int64_t t_ns) override;
};

// The figures of one `event=clock` line, over the interval since the previous one. Pure: fed the
// wall time and the pacing verdict of each step; no clock or I/O of its own.
class ClockProgress {
 public:
  // `every_ns`: simulated interval between lines (> 0).
  explicit ClockProgress(std::int64_t every_ns) : every_ns_(every_ns), next_ns_(every_ns) {}

  // After a step that ended at simulated `sim_ns` (the world's time) and wall `wall_ns`; `late`:
  // the step ended behind its paced wall time (rtf > 0 only). True when a line is due: then
  // Take() gives its figures and starts the next interval.
  bool OnStep(std::int64_t sim_ns, std::int64_t wall_ns, bool late);

  struct Line {
    double rtf = 0;        // simulated / wall seconds over the interval (0 if no wall time passed)
    std::uint64_t late = 0;  // steps of the interval that ended behind the requested pace
  };
  Line Take();

 private:
  std::int64_t every_ns_;
  std::int64_t next_ns_;
  std::int64_t origin_sim_ns_ = 0;
  std::int64_t origin_wall_ns_ = -1;  // -1: not yet anchored (at the end of the first step)
  std::int64_t sim_ns_ = 0;
  std::int64_t wall_ns_ = 0;
  std::uint64_t late_ = 0;
};

// What a recording sees of the simulation (recorder.hpp). Called on the server's thread; nothing
// it does feeds back into the run.
class StepObserver {
 public:
  virtual ~StepObserver() = default;
  // A camera frame rendered for drone `drone` at this step (before its sample goes out).
  virtual void OnCamera(std::size_t drone, const CameraImage& image) = 0;
  // After World::Step (and truth.csv): the world at its new time.
  virtual void OnStep(const World& world) = 0;
};

struct SimServerOptions {
  double rtf = 1.0;                          // 0 = as fast as possible
  double max_sim_time_s = 0;                 // 0 = no limit
  double clock_every_s = 10.0;               // event=clock every this many simulated s; 0 = never
  LockstepOptions lockstep;
  bool cameras = true;                       // the RGB cameras; stereo pairs follow the airframes alone
  std::string node = "physics";              // logfmt node name
  RadioPlan plan;                            // simulated-time faults (--radio-plan); empty: none
  // radio.model channel: the radio profile (ValidateRadioProfile passed) and the channel's seed;
  // nullopt = netem (radio_out ignored, radio_in empty). The plan's impairments must pass
  // channel::ValidateImpairment (CheckChannelPlan).
  std::optional<channel::RadioProfile> radio_profile;
  std::uint64_t radio_seed = 1;
  StepObserver* observer = nullptr;          // the recording (--record, --view); null: none
};

// The plan's impairments against what the channel carries out (its distributions): the first one
// it cannot, at its entry.
Status CheckChannelPlan(const RadioPlan& plan);
// The world's obstacle boxes as the channel's (same centre, size and yaw).
std::vector<channel::Box> ChannelObstacles(const WorldConfig& world);

class SimServer {
 public:
  // `truth` may be null. Nothing is owned except the lockstep state.
  SimServer(World& world, SimTransport& transport, WallClock& clock, TruthCsvFile* truth, SimServerOptions options,
            std::FILE* events_out);

  // Runs until max_sim_time_s or until `stop` becomes true. Returns I/O errors (truth.csv).
  Status Run(const std::atomic<bool>& stop);

  // One control step (publish, wait for answers, step). Exposed for tests.
  Status RunStep(const std::atomic<bool>& stop);

  // radio.model channel: the channel's counters; nullptr with netem.
  const channel::ChannelStats* channel_stats() const { return channel_ ? &channel_->stats() : nullptr; }

 private:
  class PrintingSink final : public EventSink {
   public:
    PrintingSink(std::FILE* out, std::string node) : out_(out), node_(std::move(node)) {}
    void OnEvent(const PhysicsEvent& event) override;

   private:
    std::FILE* out_;
    std::string node_;
  };
  struct Timed {
    std::int64_t until_ns;
    std::size_t drone;
    enum Kind { kGpsBack, kGpsAccuracyBack, kWindBack } kind;
  };
  // Per drone: what this step published and what its answer carried.
  struct Slot {
    bool camera_frame = false;
    CameraImage image;                         // this step's frame, re-sent with a re-sent sample
    bool thermal_frame = false;                // a thermal frame went with it (airframe `thermal:`)
    ThermalImage thermal;
    bool stereo_frame = false;
    bus::CameraImage stereo;                   // this step's stereo pair, re-sent likewise
    std::vector<bus::RadioFrame> radio_in;
    std::vector<WorldCommandInput> world;      // the accepted answer's
    std::vector<bus::RadioFrame> radio_out;    // the accepted answer's
    bool answer_leader = false;                // the accepted answer's raft_leader
    bool leader = false;                       // the flag as last answered
    std::uint64_t leader_since = 0;            // step + 1 at which it turned true
    std::int64_t back_ns = -1;                 // out: when it comes back; -1 = never (or not out)
    std::string out_fault;                     // out: the plan entry's name
  };
  bool CaptureCamera(std::size_t i);
  bool CaptureStereo(std::size_t i, std::uint64_t step);
  Status PublishStep(std::uint64_t step);
  Status Republish();
  Status AwaitAnswers(std::uint64_t step, const std::atomic<bool>& stop);
  void EndTimedCommands();
  Status AdvanceWorld();
  std::int64_t Pace(bool* late);
  void ReportProgress(std::int64_t wall_ns, bool late);
  Status PublishDrone(std::size_t i, bool with_camera);
  void Accept(std::size_t i, ActuatorInput& cmd);
  void TakeAnswers(std::int64_t deadline_ns);
  void ApplyAnswers();
  void RunSchedule(std::int64_t now_ns);
  void CarryOut(const PlanEntry& e);
  void TakeOut(std::size_t i, const PlanEntry& e);
  std::optional<std::size_t> RaftLeader() const;
  void TakeDeliveries(std::int64_t until_ns);
  void SendRadio(std::int64_t now_ns);
  void RadioFault(std::size_t entry, bool on);
  void SetImpairmentOf(std::size_t drone);
  void LogChannel();
  void Apply(const WorldCommandInput& cmd);
  // Carries out a checked command (Apply logs the outcome); the reason when the world refuses it.
  std::optional<std::string> Execute(const WorldCommandInput& cmd, std::optional<std::size_t> drone);
  std::optional<std::string> ExecutePayload(const WorldCommandInput& cmd, std::size_t drone);
  void Log(const LogEvent& event);
  JoiningStatus Joining() const;
  Status ReportJoining(bool done);

  World& world_;
  SimTransport& transport_;
  WallClock& clock_;
  TruthCsvFile* truth_;
  SimServerOptions options_;
  std::FILE* out_;
  PrintingSink sink_;
  Lockstep lockstep_;
  std::vector<ActuatorInput> inbox_;
  std::vector<WorldCommandInput> world_inbox_;
  std::vector<double> zeros_;
  std::vector<Timed> timed_;
  WindConfig base_wind_;
  std::vector<Slot> slots_;
  CameraTrigger trigger_;
  std::unique_ptr<StereoCapture> stereo_;    // null: no drone has a stereo pair (nothing to do)
  std::size_t next_entry_ = 0;               // options_.plan.schedule[next_entry_] is due next

  // radio.model channel.
  struct RadioEnd {
    std::int64_t at_ns;
    std::size_t entry;                       // a radio or partition entry of the plan
  };
  struct StoredFrame {
    std::int64_t sent_ns = 0;
    bus::RadioFrame frame;
  };
  std::optional<channel::Channel> channel_;
  std::vector<channel::Vec3d> positions_;
  std::vector<channel::Delivery> deliveries_;
  std::deque<StoredFrame> frames_;           // by token: frames_[token - first_token_]
  std::uint64_t first_token_ = 0;
  std::uint64_t frames_expired_ = 0;         // deliveries whose frame was dropped (see kFrameKeepNs)
  std::vector<RadioEnd> radio_ends_;
  std::vector<std::vector<std::size_t>> impairments_;  // per drone: its active radio entries
  std::vector<int> blocked_;                 // per (from, to): active partitions blocking it
  std::int64_t pace_origin_wall_ns_ = -1;
  std::int64_t pace_origin_sim_ns_ = 0;
  std::optional<ClockProgress> progress_;  // empty: clock_every_s = 0
  JoiningClock joining_{1'000'000'000};    // event=joining every wall second of the first step
};

}  // namespace swarmbox::physics
