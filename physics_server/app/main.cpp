// swarmbox-physics: the world of a trial on the sim bus. A thin shell: options -> World ->
// BusTransport -> SimServer. See `swarmbox-physics --help`.
// Exit codes: 0 done (max sim time or SIGTERM/SIGINT), 2 bad input, 3 infrastructure (bus, files).
// `--send-command <target> <command> [args...]` instead: one world command to a running server
// (send_command_main.hpp; how the orchestrator's sensor and environment faults reach it).
#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "bus_transport.hpp"
#include "recorder.hpp"
#include "send_command_main.hpp"
#include "server_options.hpp"
#include "sim_server.hpp"
#include "swarmbox/common/log_tee.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/version.hpp"
#include "swarmbox/physics/world.hpp"
#include "swarmbox/record/live_server.hpp"
#include "swarmbox/record/mcap.hpp"

namespace {

using namespace swarmbox;
using namespace swarmbox::physics;

// Exit codes (the banner above).
constexpr int kExitBadInput = 2;
constexpr int kExitInfrastructure = 3;
constexpr int kDefaultViewPort = 8765;  // --view ADDR without :PORT (Foxglove's default)

std::atomic<bool> g_stop{false};

extern "C" void OnSignal(int) { g_stop.store(true); }

int Fail(int code, const std::string& message) {
  std::fprintf(stderr, "swarmbox-physics: %s\n", message.c_str());
  return code;
}

// The options, and the drones as given before they are parsed into o.drones.
struct CommandLine {
  ServerOptions o;
  std::vector<std::string> drone_args;
  std::string drones_file;
};

// Everything the server runs with, in the order it is built (and destroyed in reverse: the
// recording's sinks and the recorder outlive the transport, which feeds them).
struct Trial {
  WorldConfig world_config;
  std::unique_ptr<World> world;
  std::vector<std::string> names;
  std::vector<GpsSpec> gps;
  std::vector<bool> stereo;  // per drone: its airframe has a stereo pair (issue #23)
  RadioPlan plan;
  std::optional<channel::RadioProfile> radio_profile;
  std::optional<TruthCsvFile> truth;
  std::unique_ptr<record::McapWriter> mcap;
  std::unique_ptr<record::LiveServer> live;
  std::unique_ptr<Recorder> recorder;
  std::unique_ptr<LogTee> tee;
  std::FILE* events = stdout;
  std::unique_ptr<BusTransport> transport;
};

// A step of the start-up: nothing when it went well, else the exit code (its message printed).
using ExitOr = std::optional<int>;

void AddWorldOptions(CLI::App& app, CommandLine* cl) {
  ServerOptions& o = cl->o;
  app.add_option("--world", o.world_path, "World file (trials/worlds/*.yaml)")->required();
  app.add_option("--drone", cl->drone_args, "A drone: name:airframe:x,y,z[:yaw_deg[:payload[:attached|ground]]] (repeatable)");
  app.add_option("--drones", cl->drones_file, "YAML list of drones {name, airframe, pose: [x,y,z], yaw_deg, payload, payload_attached}");
  app.add_option("--airframes-dir", o.airframes_dir, "Where airframe names are looked up (default: <world dir>/../airframes)");
  app.add_option("--rtf", o.rtf, "Real-time factor to pace to; 0 = as fast as possible")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--seed", o.seed, "Seed of every noise source and the wind")->capture_default_str();
  app.add_option("--truth", o.truth_path, "Ground-truth CSV to write ('' = none)")->capture_default_str();
  app.add_option("--truth-rate-hz", o.truth_rate_hz, "truth.csv rows per simulated second per drone")->check(CLI::PositiveNumber)->capture_default_str();
}

void AddBusOptions(CLI::App& app, ServerOptions* o) {
  app.add_option("--sim-interface", o->sim_interface, "Network interface of the sim bus")->capture_default_str();
  app.add_option("--participant-index", o->participant_index,
                 "Well-known DDS discovery port of this index on the sim bus, for agents started with --sim-peer "
                 "(-1: none)")
      ->check(CLI::Range(-1, 119))
      ->capture_default_str();
  app.add_option("--domain", o->domain, "DDS domain id of the sim bus")->check(CLI::Range(0, 232))->capture_default_str();
  app.add_option("--middleware", o->middleware, "DDS implementation")->check(CLI::IsMember({"cyclonedds", "fastdds"}))->capture_default_str();
}

void AddSteppingOptions(CLI::App& app, ServerOptions* o) {
  app.add_option("--max-sim-time", o->max_sim_time_s, "Stop after this many simulated seconds; 0 = run until SIGTERM")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--step-timeout", o->step_timeout_s, "Seconds of silence after which a drone is lost (motors off)")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--join-timeout", o->join_timeout_s, "Seconds a drone may take to answer its first sample")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--physics-rate-hz", o->physics_rate_hz, "ODE sub-step rate")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--control-rate-hz", o->control_rate_hz, "Lockstep (sensor/actuator) rate")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_flag("!--no-cameras", o->cameras, "Do not render or publish camera images (stereo pairs of a stereo airframe still go out)");
  app.add_option("--clock-every", o->clock_every_s, "Simulated seconds between event=clock progress lines; 0 = none")->check(CLI::NonNegativeNumber)->capture_default_str();
}

void AddRadioOptions(CLI::App& app, ServerOptions* o) {
  app.add_option("--radio-plan", o->radio_plan_path,
                 "Radio plan JSON: simulated-time faults (drone_out, world_command; radio and partition with "
                 "--radio-model channel) and the mesh impairment");
  app.add_option("--radio-model", o->radio_model,
                 "channel: host the simulated radio channel (radio_out -> channel -> radio_in, simulated time); "
                 "netem: none (the agents' mesh network carries the radio)")
      ->check(CLI::IsMember({"channel", "netem"}))
      ->capture_default_str();
  app.add_option("--radio-profile", o->radio_profile_path, "Radio profile YAML (trials/radios/*.yaml); required with --radio-model channel");
}

void AddRecordOptions(CLI::App& app, ServerOptions* o) {
  app.add_option("--record", o->record_path, "Write the recording (MCAP: true poses, the agents' telemetry, cameras, the world, every log event) to PATH; '' = none");
  app.add_option("--record-rate-hz", o->record_rate_hz, "Recording: true poses per simulated second (the agents' --telemetry-hz should match)")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--record-camera-hz", o->record_camera_hz, "Recording: camera frames per simulated second per drone; 0 = none")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--record-camera-scale", o->record_camera_scale, "Recording: camera frames are scaled by this (0, 1] before JPEG encoding")->capture_default_str();
  app.add_option("--record-jpeg-quality", o->record_jpeg_quality, "Recording: JPEG quality [1, 100]")->capture_default_str();
  app.add_option("--view", o->view_addr, "Serve the recording's channels live at ADDR:PORT (Foxglove WebSocket protocol and the built-in page at /); '' = none");
}

// The flags into *cl; the exit code of --help, --version or a usage error.
ExitOr ParseCommandLine(int argc, char** argv, CommandLine* cl) {
  CLI::App app{"swarmbox-physics: ODE world, sensors and cameras of a SwarmBox trial, in lockstep with the agents "
               "over the sim bus"};
  app.set_version_flag("--version", VersionLine("swarmbox-physics"),
                       "Print the version, git commit and build type, and exit");
  AddWorldOptions(app, cl);
  AddBusOptions(app, &cl->o);
  AddSteppingOptions(app, &cl->o);
  AddRadioOptions(app, &cl->o);
  AddRecordOptions(app, &cl->o);
  return ParseOrExitCode(app, argc, argv);
}

// Inputs: world and drones. Any problem: file:line:col: message, exit 2.
ExitOr LoadInputs(CommandLine* cl, Trial* t) {
  ServerOptions& o = cl->o;
  auto world_config = LoadWorld(o.world_path);
  if (!world_config) return Fail(kExitBadInput, world_config.error().ToString());
  t->world_config = std::move(*world_config);
  if (o.airframes_dir.empty()) {
    o.airframes_dir = (std::filesystem::path(o.world_path).parent_path() / ".." / "airframes").lexically_normal().string();
  }
  for (const std::string& a : cl->drone_args) {
    auto d = ParseDroneArg(a);
    if (!d) return Fail(kExitBadInput, d.error().ToString());
    o.drones.push_back(*d);
  }
  if (!cl->drones_file.empty()) {
    auto list = LoadDronesFile(cl->drones_file);
    if (!list) return Fail(kExitBadInput, list.error().ToString());
    o.drones.insert(o.drones.end(), list->begin(), list->end());
  }
  if (o.drones.empty()) return Fail(kExitBadInput, "no drones: give --drone or --drones");
  if (o.physics_rate_hz % o.control_rate_hz != 0) {
    return Fail(kExitBadInput, "--physics-rate-hz must be a multiple of --control-rate-hz");
  }
  return std::nullopt;
}

// One drone of o.drones into the world, its airframe loaded (airframes: exit 2 too).
ExitOr SpawnDrone(const DroneSpec& d, const ServerOptions& o, Trial* t) {
  auto af = LoadAirframe(AirframePathFor(d.airframe, o.airframes_dir));
  if (!af) return Fail(kExitBadInput, af.error().ToString());
  DroneSpawn spawn;
  spawn.name = d.name;
  spawn.airframe = *af;
  spawn.position_m = {d.x_m, d.y_m, d.z_m};
  spawn.yaw_rad = d.yaw_deg * std::numbers::pi / 180.0;
  spawn.payload = d.payload;
  spawn.payload_attached = d.payload_attached;
  auto idx = t->world->AddDrone(spawn);
  if (!idx) return Fail(kExitBadInput, d.where + ": " + idx.error().message());
  t->names.push_back(d.name);
  t->gps.push_back(af->gps);
  t->stereo.push_back(af->stereo.enabled);  // the server renders its pairs (StereoCapture)
  return std::nullopt;
}

ExitOr BuildWorld(const ServerOptions& o, Trial* t) {
  WorldOptions wopt;
  wopt.seed = o.seed;
  wopt.control_period_ns = 1'000'000'000 / o.control_rate_hz;
  wopt.substeps = o.physics_rate_hz / o.control_rate_hz;
  if (wopt.control_period_ns * o.control_rate_hz != 1'000'000'000 || wopt.control_period_ns % wopt.substeps != 0) {
    return Fail(kExitBadInput, "--control-rate-hz must divide 1e9 ns, and its period the sub-steps");
  }
  auto world = World::Create(t->world_config, wopt);
  if (!world) return Fail(kExitBadInput, world.error().ToString());
  t->world = std::move(*world);
  for (const DroneSpec& d : o.drones) {
    if (ExitOr e = SpawnDrone(d, o, t)) return e;
  }
  return std::nullopt;
}

// The radio plan, and the radio profile with --radio-model channel.
ExitOr LoadRadio(const ServerOptions& o, Trial* t) {
  if (!o.radio_plan_path.empty()) {
    auto p = LoadRadioPlan(o.radio_plan_path);
    if (!p) return Fail(kExitBadInput, p.error().ToString());
    if (Status c = CheckRadioPlan(*p, t->names); !c) return Fail(kExitBadInput, c.error().ToString());
    t->plan = std::move(*p);
  }
  if (o.radio_model != "channel") {
    if (!o.radio_profile_path.empty()) return Fail(kExitBadInput, "--radio-profile needs --radio-model channel");
    return std::nullopt;
  }
  if (o.radio_profile_path.empty()) return Fail(kExitBadInput, "--radio-model channel needs --radio-profile PATH");
  auto profile = channel::LoadRadioProfile(o.radio_profile_path);
  if (!profile) return Fail(kExitBadInput, profile.error().ToString());
  t->radio_profile = std::move(*profile);
  if (Status c = CheckChannelPlan(t->plan); !c) {
    return Fail(kExitBadInput,
                (c.error().where().empty() ? o.radio_plan_path + ": " : std::string()) + c.error().ToString());
  }
  return std::nullopt;
}

ExitOr OpenTruth(const ServerOptions& o, Trial* t) {
  if (o.truth_path.empty()) return std::nullopt;
  auto f = TruthCsvFile::Open(o.truth_path, o.truth_rate_hz);
  if (!f) return Fail(kExitInfrastructure, f.error().ToString());
  t->truth.emplace(std::move(*f));
  return std::nullopt;
}

// --view ADDR:PORT: the live server, started.
ExitOr StartLiveView(const ServerOptions& o, Trial* t) {
  const auto colon = o.view_addr.rfind(':');
  record::LiveOptions lo;
  lo.address = colon == std::string::npos ? o.view_addr : o.view_addr.substr(0, colon);
  char* end = nullptr;
  const long port =
      colon == std::string::npos ? kDefaultViewPort : std::strtol(o.view_addr.c_str() + colon + 1, &end, 10);
  if (lo.address.empty() || port < 1 || port > 65535 || (end != nullptr && *end != '\0')) {
    return Fail(kExitBadInput, "--view '" + o.view_addr + "': expected ADDR:PORT, e.g. 0.0.0.0:8765");
  }
  lo.port = static_cast<int>(port);
  lo.name = "swarmbox " + t->world_config.name;
  auto server = record::LiveServer::Start(lo);
  if (!server) return Fail(kExitInfrastructure, server.error().Context("--view " + o.view_addr).ToString());
  t->live = std::move(*server);
  return std::nullopt;
}

// The recording: its sinks (--record's file, --view's server), then the recorder.
ExitOr StartRecording(const ServerOptions& o, Trial* t) {
  if (o.record_path.empty() && o.view_addr.empty()) return std::nullopt;
  RecordOptions ro;
  ro.rate_hz = o.record_rate_hz;
  ro.camera_hz = o.cameras ? o.record_camera_hz : 0.0;
  ro.camera_scale = o.record_camera_scale;
  ro.jpeg_quality = o.record_jpeg_quality;
  if (Status v = ValidateRecordOptions(ro); !v) return Fail(kExitBadInput, v.error().ToString());
  std::vector<record::Sink*> sinks;
  if (!o.record_path.empty()) {
    auto w = record::McapWriter::Create(o.record_path);
    if (!w) return Fail(kExitInfrastructure, w.error().Context("--record " + o.record_path).ToString());
    t->mcap = std::move(*w);
    sinks.push_back(t->mcap.get());
  }
  if (!o.view_addr.empty()) {
    if (ExitOr e = StartLiveView(o, t)) return e;
    sinks.push_back(t->live.get());
  }
  auto r = Recorder::Create(sinks, t->names, t->world_config, ro);
  if (!r) return Fail(kExitInfrastructure, r.error().ToString());
  t->recorder = std::move(*r);
  return std::nullopt;
}

// With a recording, every event line also goes to it (its /log channel); stdout is unchanged.
ExitOr TeeEvents(Trial* t) {
  if (!t->recorder) return std::nullopt;
  auto tee = LogTee::Create(stdout, [r = t->recorder.get()](std::string_view line) { r->OnLogLine(line); });
  if (!tee) return Fail(kExitInfrastructure, tee.error().ToString());
  t->tee = std::move(*tee);
  t->events = t->tee->file();
  return std::nullopt;
}

ExitOr OpenTransport(const ServerOptions& o, Trial* t) {
  bus::ParticipantConfig pc;
  pc.backend = o.middleware;
  pc.domain_id = o.domain;
  pc.interface = o.sim_interface;
  pc.participant_index = o.participant_index;
  // No writer lingers at exit (Cyclone's default keeps one with unacknowledged samples up to 1 s,
  // ~0.2 s with agents still up): the samples and images sent last are of no use once the server
  // goes; truth.csv and the events are written before the transport is closed.
  pc.writer_linger_ms = 0;
  auto transport = BusTransport::Create(pc, t->names, t->gps, t->stereo);
  if (!transport) {
    const ErrorCode c = transport.error().code();
    return Fail(c == ErrorCode::kInvalidArgument || c == ErrorCode::kNotFound ? kExitBadInput : kExitInfrastructure,
                transport.error().ToString());
  }
  t->transport = std::move(*transport);
  if (!t->recorder) return std::nullopt;
  if (Status s = t->transport->SubscribeTelemetry([r = t->recorder.get()](const bus::Telemetry& m) { r->OnTelemetry(m); });
      !s) {
    return Fail(kExitInfrastructure, s.error().ToString());
  }
  return std::nullopt;
}

// Parse -> inputs -> world -> radio -> truth -> recording -> transport, the first failure's exit code.
ExitOr Build(int argc, char** argv, CommandLine* cl, Trial* t) {
  if (ExitOr e = ParseCommandLine(argc, argv, cl)) return e;
  if (ExitOr e = LoadInputs(cl, t)) return e;
  const ServerOptions& o = cl->o;
  for (auto step : {BuildWorld, LoadRadio, OpenTruth, StartRecording}) {
    if (ExitOr e = step(o, t)) return e;
  }
  if (ExitOr e = TeeEvents(t)) return e;
  return OpenTransport(o, t);
}

SimServerOptions ServerOptionsOf(const ServerOptions& o, Trial* t) {
  SimServerOptions so;
  so.rtf = o.rtf;
  so.max_sim_time_s = o.max_sim_time_s;
  so.lockstep.timeout_ns = static_cast<std::int64_t>(o.step_timeout_s * 1e9);
  so.lockstep.join_timeout_ns = static_cast<std::int64_t>(o.join_timeout_s * 1e9);
  so.cameras = o.cameras;
  so.clock_every_s = o.clock_every_s;
  so.plan = std::move(t->plan);
  so.radio_profile = std::move(t->radio_profile);
  // The plan's seed when it has one (the trial's, written by the orchestrator), else --seed.
  so.radio_seed = so.plan.seed.value_or(o.seed);
  so.observer = t->recorder.get();
  return so;
}

// Runs the server until the max sim time or a signal, between event=ready and event=stopped.
Status Run(const ServerOptions& o, Trial* t) {
  std::signal(SIGTERM, OnSignal);
  std::signal(SIGINT, OnSignal);
  SteadyWallClock clock;
  SimServer server(*t->world, *t->transport, clock, t->truth ? &*t->truth : nullptr, ServerOptionsOf(o, t), t->events);
  if (t->recorder) {
    t->recorder->Start();
    t->recorder->OnStep(*t->world);  // the poses at t = 0
  }
  std::fprintf(t->events, "%s\n", LogEvent(0.0, "physics", "ready")
                                      .Add("world", t->world_config.name)
                                      .Add("drones", static_cast<std::int64_t>(t->names.size()))
                                      .Add("middleware", o.middleware)
                                      .Add("domain", o.domain)
                                      .Add("rtf", o.rtf, 2)
                                      .Add("seed", o.seed)
                                      .Add("radio_model", o.radio_model)
                                      .str()
                                      .c_str());
  std::fflush(t->events);
  const Status s = server.Run(g_stop);
  std::fprintf(t->events, "%s\n", LogEvent(t->world->time_s(), "physics", "stopped")
                                      .Add("reason", g_stop.load() ? "signal" : "max_sim_time")
                                      .Add("steps", static_cast<std::uint64_t>(t->world->step_count()))
                                      .str()
                                      .c_str());
  std::fflush(t->events);
  return s;
}

// The recording completed, the run's status reported; the exit code.
int Finish(const ServerOptions& o, Trial* t, const Status& run) {
  // The recording is complete before the process leaves (a signal's exit skips destructors).
  if (t->recorder) {
    if (Status f = t->recorder->Finish(); !f) std::fprintf(stderr, "swarmbox-physics: recording: %s\n", f.error().ToString().c_str());
  }
  if (t->mcap) {
    if (Status c = t->mcap->Close(); !c) return Fail(kExitInfrastructure, c.error().Context("--record " + o.record_path).ToString());
  }
  if (!run) return Fail(kExitInfrastructure, run.error().ToString());
  if (g_stop.load()) {
    // Stopped by a signal (a trial's end): truth.csv and event=stopped are out, so leave without
    // DDS's orderly goodbye, as the agents do (agent/app/main.cpp): announcing the removal of the
    // server's 3 endpoints per drone to agents that are gone or going is of no use to anyone.
    if (t->truth) {
      if (Status f = t->truth->Flush(); !f) return Fail(kExitInfrastructure, f.error().ToString());
    }
    std::fflush(stderr);
    std::_Exit(0);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (IsSendCommand(argc, argv)) return RunSendCommand(argc, argv);
  CommandLine cl;
  Trial trial;
  if (ExitOr e = Build(argc, argv, &cl, &trial)) return *e;
  const Status run = Run(cl.o, &trial);
  return Finish(cl.o, &trial, run);
}
