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
#include <numbers>

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

std::atomic<bool> g_stop{false};

extern "C" void OnSignal(int) { g_stop.store(true); }

int Fail(int code, const std::string& message) {
  std::fprintf(stderr, "swarmbox-physics: %s\n", message.c_str());
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace swarmbox;
  using namespace swarmbox::physics;
  if (IsSendCommand(argc, argv)) return RunSendCommand(argc, argv);
  ServerOptions o;
  std::vector<std::string> drone_args;
  std::string drones_file;
  CLI::App app{"swarmbox-physics: ODE world, sensors and cameras of a SwarmBox trial, in lockstep with the agents "
               "over the sim bus"};
  app.set_version_flag("--version", VersionLine("swarmbox-physics"),
                       "Print the version, git commit and build type, and exit");
  app.add_option("--world", o.world_path, "World file (trials/worlds/*.yaml)")->required();
  app.add_option("--drone", drone_args, "A drone: name:airframe:x,y,z[:yaw_deg[:payload[:attached|ground]]] (repeatable)");
  app.add_option("--drones", drones_file, "YAML list of drones {name, airframe, pose: [x,y,z], yaw_deg, payload, payload_attached}");
  app.add_option("--airframes-dir", o.airframes_dir, "Where airframe names are looked up (default: <world dir>/../airframes)");
  app.add_option("--rtf", o.rtf, "Real-time factor to pace to; 0 = as fast as possible")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--seed", o.seed, "Seed of every noise source and the wind")->capture_default_str();
  app.add_option("--truth", o.truth_path, "Ground-truth CSV to write ('' = none)")->capture_default_str();
  app.add_option("--truth-rate-hz", o.truth_rate_hz, "truth.csv rows per simulated second per drone")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--sim-interface", o.sim_interface, "Network interface of the sim bus")->capture_default_str();
  app.add_option("--participant-index", o.participant_index,
                 "Well-known DDS discovery port of this index on the sim bus, for agents started with --sim-peer "
                 "(-1: none)")
      ->check(CLI::Range(-1, 119))
      ->capture_default_str();
  app.add_option("--domain", o.domain, "DDS domain id of the sim bus")->check(CLI::Range(0, 232))->capture_default_str();
  app.add_option("--middleware", o.middleware, "DDS implementation")->check(CLI::IsMember({"cyclonedds", "fastdds"}))->capture_default_str();
  app.add_option("--max-sim-time", o.max_sim_time_s, "Stop after this many simulated seconds; 0 = run until SIGTERM")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--step-timeout", o.step_timeout_s, "Seconds of silence after which a drone is lost (motors off)")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--join-timeout", o.join_timeout_s, "Seconds a drone may take to answer its first sample")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--physics-rate-hz", o.physics_rate_hz, "ODE sub-step rate")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--control-rate-hz", o.control_rate_hz, "Lockstep (sensor/actuator) rate")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_flag("!--no-cameras", o.cameras, "Do not render or publish camera images");
  app.add_option("--clock-every", o.clock_every_s, "Simulated seconds between event=clock progress lines; 0 = none")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--radio-plan", o.radio_plan_path,
                 "Radio plan JSON: simulated-time faults (drone_out, world_command; radio and partition with "
                 "--radio-model channel) and the mesh impairment");
  app.add_option("--radio-model", o.radio_model,
                 "channel: host the simulated radio channel (radio_out -> channel -> radio_in, simulated time); "
                 "netem: none (the agents' mesh network carries the radio)")
      ->check(CLI::IsMember({"channel", "netem"}))
      ->capture_default_str();
  app.add_option("--radio-profile", o.radio_profile_path, "Radio profile YAML (trials/radios/*.yaml); required with --radio-model channel");
  app.add_option("--record", o.record_path, "Write the recording (MCAP: true poses, the agents' telemetry, cameras, the world, every log event) to PATH; '' = none");
  app.add_option("--record-rate-hz", o.record_rate_hz, "Recording: true poses per simulated second (the agents' --telemetry-hz should match)")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--record-camera-hz", o.record_camera_hz, "Recording: camera frames per simulated second per drone; 0 = none")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--record-camera-scale", o.record_camera_scale, "Recording: camera frames are scaled by this (0, 1] before JPEG encoding")->capture_default_str();
  app.add_option("--record-jpeg-quality", o.record_jpeg_quality, "Recording: JPEG quality [1, 100]")->capture_default_str();
  app.add_option("--view", o.view_addr, "Serve the recording's channels live at ADDR:PORT (Foxglove WebSocket protocol and the built-in page at /); '' = none");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  // Inputs: world, drones, airframes. Any problem: file:line:col: message, exit 2.
  auto world_config = LoadWorld(o.world_path);
  if (!world_config) return Fail(2, world_config.error().ToString());
  if (o.airframes_dir.empty()) {
    o.airframes_dir = (std::filesystem::path(o.world_path).parent_path() / ".." / "airframes").lexically_normal().string();
  }
  for (const std::string& a : drone_args) {
    auto d = ParseDroneArg(a);
    if (!d) return Fail(2, d.error().ToString());
    o.drones.push_back(*d);
  }
  if (!drones_file.empty()) {
    auto list = LoadDronesFile(drones_file);
    if (!list) return Fail(2, list.error().ToString());
    o.drones.insert(o.drones.end(), list->begin(), list->end());
  }
  if (o.drones.empty()) return Fail(2, "no drones: give --drone or --drones");
  if (o.physics_rate_hz % o.control_rate_hz != 0) return Fail(2, "--physics-rate-hz must be a multiple of --control-rate-hz");

  WorldOptions wopt;
  wopt.seed = o.seed;
  wopt.control_period_ns = 1'000'000'000 / o.control_rate_hz;
  wopt.substeps = o.physics_rate_hz / o.control_rate_hz;
  if (wopt.control_period_ns * o.control_rate_hz != 1'000'000'000 || wopt.control_period_ns % wopt.substeps != 0) {
    return Fail(2, "--control-rate-hz must divide 1e9 ns, and its period the sub-steps");
  }
  auto world = World::Create(*world_config, wopt);
  if (!world) return Fail(2, world.error().ToString());
  std::vector<std::string> names;
  std::vector<GpsSpec> gps;
  for (const DroneSpec& d : o.drones) {
    auto af = LoadAirframe(AirframePathFor(d.airframe, o.airframes_dir));
    if (!af) return Fail(2, af.error().ToString());
    if (af->stereo.enabled) {
      // Issue #23: the pair is parsed and benchmarked (swarmbox-bench stereo) but this server does
      // not render or publish it yet; a trial that asks for depth must not run without it.
      return Fail(2, d.where + ": airframe '" + d.airframe +
                         "' has a stereo depth camera ('stereo:'), which trials cannot fly yet: the physics "
                         "server does not render stereo pairs (issue #23; swarmbox-bench stereo measures the "
                         "model); use the airframe without '_depth'");
    }
    DroneSpawn spawn;
    spawn.name = d.name;
    spawn.airframe = *af;
    spawn.position_m = {d.x_m, d.y_m, d.z_m};
    spawn.yaw_rad = d.yaw_deg * std::numbers::pi / 180.0;
    spawn.payload = d.payload;
    spawn.payload_attached = d.payload_attached;
    auto idx = (*world)->AddDrone(spawn);
    if (!idx) return Fail(2, d.where + ": " + idx.error().message());
    names.push_back(d.name);
    gps.push_back(af->gps);
  }

  RadioPlan plan;
  if (!o.radio_plan_path.empty()) {
    auto p = LoadRadioPlan(o.radio_plan_path);
    if (!p) return Fail(2, p.error().ToString());
    if (Status c = CheckRadioPlan(*p, names); !c) return Fail(2, c.error().ToString());
    plan = std::move(*p);
  }
  std::optional<channel::RadioProfile> radio_profile;
  if (o.radio_model == "channel") {
    if (o.radio_profile_path.empty()) return Fail(2, "--radio-model channel needs --radio-profile PATH");
    auto profile = channel::LoadRadioProfile(o.radio_profile_path);
    if (!profile) return Fail(2, profile.error().ToString());
    radio_profile = std::move(*profile);
    if (Status c = CheckChannelPlan(plan); !c) {
      return Fail(2, (c.error().where().empty() ? o.radio_plan_path + ": " : std::string()) + c.error().ToString());
    }
  } else if (!o.radio_profile_path.empty()) {
    return Fail(2, "--radio-profile needs --radio-model channel");
  }

  std::optional<TruthCsvFile> truth;
  if (!o.truth_path.empty()) {
    auto f = TruthCsvFile::Open(o.truth_path, o.truth_rate_hz);
    if (!f) return Fail(3, f.error().ToString());
    truth.emplace(std::move(*f));
  }

  // The recording: its sinks, then the recorder (both outlive the transport, which feeds it).
  std::unique_ptr<record::McapWriter> mcap;
  std::unique_ptr<record::LiveServer> live;
  std::unique_ptr<Recorder> recorder;
  if (!o.record_path.empty() || !o.view_addr.empty()) {
    RecordOptions ro;
    ro.rate_hz = o.record_rate_hz;
    ro.camera_hz = o.cameras ? o.record_camera_hz : 0.0;
    ro.camera_scale = o.record_camera_scale;
    ro.jpeg_quality = o.record_jpeg_quality;
    if (Status v = ValidateRecordOptions(ro); !v) return Fail(2, v.error().ToString());
    std::vector<record::Sink*> sinks;
    if (!o.record_path.empty()) {
      auto w = record::McapWriter::Create(o.record_path);
      if (!w) return Fail(3, w.error().Context("--record " + o.record_path).ToString());
      mcap = std::move(*w);
      sinks.push_back(mcap.get());
    }
    if (!o.view_addr.empty()) {
      const auto colon = o.view_addr.rfind(':');
      record::LiveOptions lo;
      lo.address = colon == std::string::npos ? o.view_addr : o.view_addr.substr(0, colon);
      char* end = nullptr;
      const long port = colon == std::string::npos ? 8765 : std::strtol(o.view_addr.c_str() + colon + 1, &end, 10);
      if (lo.address.empty() || port < 1 || port > 65535 || (end != nullptr && *end != '\0')) {
        return Fail(2, "--view '" + o.view_addr + "': expected ADDR:PORT, e.g. 0.0.0.0:8765");
      }
      lo.port = static_cast<int>(port);
      lo.name = "swarmbox " + world_config->name;
      auto server = record::LiveServer::Start(lo);
      if (!server) return Fail(3, server.error().Context("--view " + o.view_addr).ToString());
      live = std::move(*server);
      sinks.push_back(live.get());
    }
    auto r = Recorder::Create(sinks, names, *world_config, ro);
    if (!r) return Fail(3, r.error().ToString());
    recorder = std::move(*r);
  }
  // With a recording, every event line also goes to it (its /log channel); stdout is unchanged.
  std::unique_ptr<LogTee> tee;
  std::FILE* events = stdout;
  if (recorder) {
    auto t = LogTee::Create(stdout, [r = recorder.get()](std::string_view line) { r->OnLogLine(line); });
    if (!t) return Fail(3, t.error().ToString());
    tee = std::move(*t);
    events = tee->file();
  }

  bus::ParticipantConfig pc;
  pc.backend = o.middleware;
  pc.domain_id = o.domain;
  pc.interface = o.sim_interface;
  pc.participant_index = o.participant_index;
  // No writer lingers at exit (Cyclone's default keeps one with unacknowledged samples up to 1 s,
  // ~0.2 s with agents still up): the samples and images sent last are of no use once the server
  // goes; truth.csv and the events are written before the transport is closed.
  pc.writer_linger_ms = 0;
  auto transport = BusTransport::Create(pc, names, gps);
  if (!transport) {
    const ErrorCode c = transport.error().code();
    return Fail(c == ErrorCode::kInvalidArgument || c == ErrorCode::kNotFound ? 2 : 3, transport.error().ToString());
  }
  if (recorder) {
    if (Status s = (*transport)->SubscribeTelemetry([r = recorder.get()](const bus::Telemetry& t) { r->OnTelemetry(t); }); !s) {
      return Fail(3, s.error().ToString());
    }
  }

  std::signal(SIGTERM, OnSignal);
  std::signal(SIGINT, OnSignal);
  SimServerOptions so;
  so.rtf = o.rtf;
  so.max_sim_time_s = o.max_sim_time_s;
  so.lockstep.timeout_ns = static_cast<std::int64_t>(o.step_timeout_s * 1e9);
  so.lockstep.join_timeout_ns = static_cast<std::int64_t>(o.join_timeout_s * 1e9);
  so.cameras = o.cameras;
  so.clock_every_s = o.clock_every_s;
  so.plan = std::move(plan);
  so.radio_profile = std::move(radio_profile);
  // The plan's seed when it has one (the trial's, written by the orchestrator), else --seed.
  so.radio_seed = so.plan.seed.value_or(o.seed);
  so.observer = recorder.get();
  SteadyWallClock clock;
  SimServer server(**world, **transport, clock, truth ? &*truth : nullptr, so, events);
  if (recorder) {
    recorder->Start();
    recorder->OnStep(**world);  // the poses at t = 0
  }
  std::fprintf(events, "%s\n", LogEvent(0.0, "physics", "ready")
                          .Add("world", world_config->name)
                          .Add("drones", static_cast<std::int64_t>(names.size()))
                          .Add("middleware", o.middleware)
                          .Add("domain", o.domain)
                          .Add("rtf", o.rtf, 2)
                          .Add("seed", o.seed)
                          .Add("radio_model", o.radio_model)
                          .str()
                          .c_str());
  std::fflush(events);
  const Status s = server.Run(g_stop);
  std::fprintf(events, "%s\n", LogEvent((*world)->time_s(), "physics", "stopped")
                          .Add("reason", g_stop.load() ? "signal" : "max_sim_time")
                          .Add("steps", static_cast<std::uint64_t>((*world)->step_count()))
                          .str()
                          .c_str());
  std::fflush(events);
  // The recording is complete before the process leaves (a signal's exit skips destructors).
  if (recorder) {
    if (Status f = recorder->Finish(); !f) std::fprintf(stderr, "swarmbox-physics: recording: %s\n", f.error().ToString().c_str());
  }
  if (mcap) {
    if (Status c = mcap->Close(); !c) return Fail(3, c.error().Context("--record " + o.record_path).ToString());
  }
  if (!s) return Fail(3, s.error().ToString());
  if (g_stop.load()) {
    // Stopped by a signal (a trial's end): truth.csv and event=stopped are out, so leave without
    // DDS's orderly goodbye, as the agents do (agent/app/main.cpp): announcing the removal of the
    // server's 3 endpoints per drone to agents that are gone or going is of no use to anyone.
    if (truth) {
      if (Status f = truth->Flush(); !f) return Fail(3, f.error().ToString());
    }
    std::fflush(stderr);
    std::_Exit(0);
  }
  return 0;
}
