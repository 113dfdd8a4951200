#include "swarmbox/runner/runner.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/dsl/step.hpp"
#include "swarmbox/report/trial_record.hpp"
#include "swarmbox/runner/derived_world.hpp"
#include "swarmbox/runner/docker_engine.hpp"
#include "swarmbox/runner/fault_image.hpp"
#include "swarmbox/runner/fault_injector.hpp"
#include "swarmbox/runner/log_hub.hpp"
#include "swarmbox/runner/monitor.hpp"
#include "swarmbox/runner/naming.hpp"
#include "swarmbox/runner/radio_schedule.hpp"
#include "swarmbox/runner/start_progress.hpp"
#include "swarmbox/runner/trial_progress.hpp"
#include "swarmbox/runner/trajectories.hpp"
#include "swarmbox/runner/user_images.hpp"

namespace swarmbox::runner {

namespace fs = std::filesystem;
using dsl::Verdict;

namespace {

Status WriteFile(const fs::path& path, std::string_view text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) return Error(ErrorCode::kIo, "cannot write file", path.string());
  return Ok{};
}

std::optional<double> NumberField(const LogfmtFields& fields, std::initializer_list<const char*> keys) {
  for (const char* k : keys) {
    if (auto v = FindField(fields, k)) {
      if (auto d = yaml::ScalarAsDouble(*v)) return d;
    }
  }
  return std::nullopt;
}

// events.jsonl, appended line by line as events happen (also from the trace callback).
class EventsFile {
 public:
  explicit EventsFile(const fs::path& path) : file_(std::fopen(path.c_str(), "wb")) {}
  ~EventsFile() {
    if (file_ != nullptr) std::fclose(file_);
  }
  EventsFile(const EventsFile&) = delete;
  EventsFile& operator=(const EventsFile&) = delete;
  bool ok() const { return file_ != nullptr; }
  void Write(const std::string& line) {
    if (file_ == nullptr) return;
    std::fwrite(line.data(), 1, line.size(), file_);
    std::fputc('\n', file_);
    std::fflush(file_);
  }

 private:
  std::FILE* file_;
};

// {"wall_s":0.000,"component":"orchestrator","event":"warning","reason":"..."}
std::string WarningEventJson(double wall_s, const std::string& reason) {
  yaml::Node root = yaml::Node::Mapping();
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", wall_s);
  root.Set("wall_s", yaml::Node::Scalar(buf));
  root.Set("component", yaml::Node::Scalar("orchestrator", {}, /*quoted=*/true));
  root.Set("event", yaml::Node::Scalar("warning", {}, /*quoted=*/true));
  root.Set("reason", yaml::Node::Scalar(reason, {}, /*quoted=*/true));
  return yaml::EmitJson(root);
}

// {"wall_s":1.234,"component":"scout_2-brain","event":"exited","exit_code":137}: a container
// that may leave without ending the trial (Monitor::ExitRule) did.
std::string ExitedEventJson(double wall_s, const std::string& component, std::int64_t exit_code) {
  yaml::Node root = yaml::Node::Mapping();
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", wall_s);
  root.Set("wall_s", yaml::Node::Scalar(buf));
  root.Set("component", yaml::Node::Scalar(component, {}, /*quoted=*/true));
  root.Set("event", yaml::Node::Scalar("exited", {}, /*quoted=*/true));
  root.Set("exit_code", yaml::Node::Scalar(std::to_string(exit_code)));
  return yaml::EmitJson(root);
}

// $SWARMBOX_PARALLEL (a positive number), else `fallback`.
int ParallelFromEnvironment(int fallback) {
  const char* v = std::getenv("SWARMBOX_PARALLEL");
  if (v == nullptr) return fallback;
  const int n = std::atoi(v);
  return n > 0 ? n : fallback;
}

// result.json's provenance (report/provenance.hpp): this build and machine, the engine's
// GET /version, the tree's images, the fault mechanism the injector used.
report::Provenance TrialProvenance(docker::DockerApi& api, dsl::Trial* tree,
                                   const FaultInjector* injector, std::optional<double> rtf_requested,
                                   std::optional<double> rtf_achieved) {
  report::Provenance p = report::LocalProvenance();
  if (auto v = api.Version()) {
    p.engine.docker_version = v->version;
    p.engine.docker_api_version = v->api_version;
    p.engine.kernel = v->kernel_version;
  }
  if (tree != nullptr) {
    std::set<std::string> images;
    for (dsl::Plugin* plugin : tree->Plugins()) images.insert(plugin->spec().image);
    p.images.assign(images.begin(), images.end());
  }
  p.fault_mechanism = injector != nullptr && injector->mechanism()
                          ? std::string(faults::MechanismName(*injector->mechanism()))
                          : "none";
  p.rtf_requested = rtf_requested;
  p.rtf_achieved = rtf_achieved;
  return p;
}

}  // namespace

std::optional<std::string> RadioRtfWarning(std::string_view radio_model, std::optional<double> rtf_asked) {
  if (radio_model != "netem" || !rtf_asked || *rtf_asked == 1.0) return std::nullopt;
  char rtf[32];
  std::snprintf(rtf, sizeof rtf, "%g", *rtf_asked);
  return "radio.model netem runs the radio on the wall clock: at rtf " + std::string(rtf) +
         " its delays, timeouts and link figures are distorted against simulated time (radio.model channel "
         "keeps them on simulated time at any rtf)";
}

Result<RunOutcome> RunTrial(const TrialInfo& info, const Planner& planner, docker::DockerApi& api,
                            Clock& clock, const RunOptions& o) {
  const std::string run_id = o.run_id.empty() ? NewRunId() : o.run_id;
  const fs::path dir = fs::path(o.out_dir) / TrialDirName(info.name, run_id);
  std::error_code ec;
  fs::create_directories(dir / "logs", ec);
  if (ec) return Error(ErrorCode::kIo, "cannot create the trial folder: " + ec.message(), dir.string());
  SWARMBOX_TRY(WriteFile(dir / "trial.yaml", info.resolved_yaml));
  for (const auto& [file, text] : info.files) SWARMBOX_TRY(WriteFile(dir / file, text));
  EventsFile events(dir / "events.jsonl");
  if (!events.ok()) return Error(ErrorCode::kIo, "cannot write events.jsonl", dir.string());
  if (auto warning = RadioRtfWarning(info.radio_model, info.rtf)) events.Write(WarningEventJson(0.0, *warning));
  if (auto ping = api.Ping(); !ping) return ping.error().Context("reaching the Docker engine");

  std::vector<std::string> taken;
  auto refresh_taken = [&] {
    taken.clear();
    if (auto nets = api.ListNetworks({})) {
      for (const auto& n : *nets) {
        if (!n.subnet.empty()) taken.push_back(n.subnet);
      }
    }
  };
  refresh_taken();

  const double t0 = clock.NowS();
  auto wall = [&] { return clock.NowS() - t0; };
  auto say = [&](const std::string& line) {
    if (o.progress != nullptr) *o.progress << "[" << info.name << "] " << line << std::endl;
  };
  say("run " + run_id + " -> " + dir.string());

  LogHub hub;  // outlives the engine, whose follower threads push into it
  EngineOptions eo;
  eo.trial_dir = dir.string();
  eo.start_wall_s = t0;
  eo.interrupted = o.interrupted;
  eo.max_parallel = o.max_parallel > 0 ? o.max_parallel : ParallelFromEnvironment(eo.max_parallel);
  // Created and started containers, counted (Trace calls are serialised by the engine).
  StartProgress counts;
  eo.on_trace = [&](const dsl::Component& c, dsl::EventKind e, const Verdict& v) {
    events.Write(LifecycleEventJson(wall(), dsl::EventName(e), c.id(), v));
    if (!v.ok()) {
      say(std::string(dsl::EventName(e)) + " " + c.id() + ": " + v.ToString());
      return;
    }
    if (dynamic_cast<const dsl::Plugin*>(&c) == nullptr) return;
    std::optional<std::string> line;
    if (e == dsl::EventKind::kBuild) line = counts.OnCreated(wall());
    if (e == dsl::EventKind::kRun) line = counts.OnStarted(wall());
    if (line) say(*line);
  };

  std::unique_ptr<dsl::Trial> tree;
  std::unique_ptr<DockerEngine> engine;
  std::optional<Monitor> monitor;

  // Faults: one injector per built tree (a restart or another subnet pair makes a new one).
  const bool has_faults = !info.mesh.empty() || !info.faults.empty() || !info.planned_faults.empty();
  std::unique_ptr<FaultInjector> injector;
  auto make_injector = [&]() -> std::unique_ptr<FaultInjector> {
    InjectorConfig c;
    c.drones = info.drones;
    c.mesh = info.mesh;
    c.faults = info.faults;
    c.planned = info.planned_faults;
    c.physics_component = std::string(kPhysicsId);
    c.seed = info.seed;
    c.host = o.host;
    for (const std::string& d : info.drones) {
      if (dsl::Plugin* agent = tree->FindPlugin(d)) c.agents[d] = agent->spec().name;
      if (dsl::Plugin* sidecar = tree->FindPlugin(SidecarId(d))) {
        c.sidecars[d] = sidecar->spec().name;
        for (const dsl::Attachment& a : sidecar->spec().networks) {
          if (a.network == kMeshNetworkId) c.mesh_ipv4[d] = a.ipv4;
        }
      }
    }
    c.mesh_interface = std::string(kMeshInterfaceName);
    if (dsl::Plugin* physics = tree->FindPlugin(kPhysicsId)) c.physics_container = physics->spec().name;
    c.physics_command_argv = [middleware = info.middleware](const faults::WorldCommandCall& call) {
      return PhysicsCommandArgv(middleware, call);
    };
    return std::make_unique<FaultInjector>(
        api, std::move(c), [&](const std::string& line) { events.Write(line); },
        [&] { return monitor ? monitor->sim_s() : 0.0; }, [&] { return wall(); });
  };
  // With sidecars the tree's `faults` Step runs the set-up between the sidecars and the agents;
  // without (process faults only) it runs once the tree has started.
  auto bind_faults = [&]() {
    if (!has_faults || !tree) return;
    if (auto* step = dynamic_cast<dsl::Step*>(tree->Find(kFaultsStepId))) {
      step->Bind(
          [&]() {
            injector = make_injector();
            return injector->Setup();
          },
          [&]() { return injector ? injector->Teardown() : Verdict::Success(); });
    }
  };
  auto start_faults = [&]() -> Verdict {
    if (!has_faults) return Verdict::Success();
    if (dynamic_cast<dsl::Step*>(tree->Find(kFaultsStepId)) != nullptr) return Verdict::Success();
    injector = make_injector();
    return injector->Setup();
  };
  Verdict start;
  for (int attempt = 0; attempt < std::max(1, o.subnet_attempts); ++attempt) {
    // Keyed by run and trial: an experiment's parallel trials share the run id and would all
    // start from the same pair, racing for it.
    auto subnets = PickSubnets(run_id + "/" + (o.trial_id.empty() ? info.name : o.trial_id),
                               attempt, taken);
    if (!subnets) {
      start = Verdict::FromError(subnets.error(), "subnets");
      break;
    }
    if (engine && tree) (void)tree->Stop(*engine);
    engine.reset();
    auto planned = planner(run_id, *subnets);
    if (!planned) return planned.error().Context("planning the trial");
    tree = std::move(*planned);
    counts = StartProgress(tree->Plugins().size());
    engine = std::make_unique<DockerEngine>(api, hub, clock, eo);
    bind_faults();
    start = tree->Start(*engine);
    if (start.ok() || !engine->subnet_conflict()) break;
    say("subnet conflict (" + start.reason + "), trying another pair");
    (void)tree->Stop(*engine);
    engine.reset();
    tree.reset();
    refresh_taken();
  }
  // After a failed start, creations queued ahead may still trace their build: let them finish
  // before the runner writes to events.jsonl itself.
  if (engine) engine->FinishCreates();

  RtfMeter rtf;
  std::vector<Detection> detections;
  TrialResult result;
  result.trial = info.name;
  result.trial_id = o.trial_id.empty() ? info.name : o.trial_id;
  result.run_id = run_id;
  result.seed = info.seed;
  result.host = o.host;
  result.radio_model = info.radio_model;
  result.radio_profile = info.radio_profile;

  auto raise = [&](const std::string& component, Verdict v, bool restart) {
    dsl::Component* c = tree->Find(component);
    if (c == nullptr) c = tree.get();
    if (restart) {
      c->RaiseRestart(v.reason);
    } else {
      c->RaiseShutdown(std::move(v));
    }
  };
  // Containers a fault brought back (start after kill/stop, restart): follow their logs again.
  auto resume_logs = [&]() {
    if (!injector || !engine) return;
    for (const std::string& c : injector->TakeResumed()) {
      if (Status s = engine->ResumeLogs(c); !s) {
        tree->RaiseShutdown(Verdict::FromError(s.error().Context("following " + c + " again"), c));
      } else if (monitor) {
        monitor->Started(c);
      }
    }
  };
  TrialProgress joining;  // the physics server's event=joining/joined lines only
  auto process = [&](const HubItem& item) {
    if (item.kind == HubItem::Kind::kLine) {
      const LogfmtFields fields = ParseLogfmt(item.text);
      if (auto j = LogEventJson(item.wall_s, item.component, fields)) {
        events.Write(*j);
        auto ev = FindField(fields, "event");
        if (ev && (*ev == "victim_detected" || *ev == "victim_confirmed")) {
          auto x = NumberField(fields, {"x", "x_m"});
          auto y = NumberField(fields, {"y", "y_m"});
          if (x && y) {
            detections.push_back({FindField(fields, "node").value_or(item.component), *x, *y,
                                  *ev == "victim_confirmed"});
          }
        }
      }
      if (monitor && tree) {
        if (auto v = monitor->OnLine(item.component, item.text)) raise(item.component, *v, false);
      }
      // The physics server's start, folded apart from the monitor (which stops at the trial's end:
      // the lines of the start may come after another stream's ending line).
      if (auto ev = FindField(fields, "event"); ev && (*ev == "joining" || *ev == "joined")) {
        joining.OnLine(item.component, item.text);
        if (!result.timing.joined_s) {
          if (auto line = JoinedLine(joining)) {
            say(*line);
            result.timing.joined_s = item.wall_s;
          }
        }
      }
      if (injector && tree && !tree->end_verdict()) {
        // The line may move simulated time on: `at:` faults fire at the line that crosses.
        if (auto v = injector->OnLogLine(item.component, item.text)) tree->RaiseShutdown(*v);
        if (auto v = injector->Advance(); v && !tree->end_verdict()) tree->RaiseShutdown(*v);
        resume_logs();
      }
      return;
    }
    // The end of a log stream: the container stopped, or the stream broke.
    if (!engine || !engine->IsCurrent(item) || !monitor || !tree || tree->end_verdict()) return;
    // A container a fault took down (kill, stop, restart) did not crash.
    if (injector && injector->Disrupted(item.component)) return;
    auto state = engine->Inspect(item.component);
    if (state && !state->running) {
      if (auto v = monitor->OnExit(item.component, state->exit_code, state->oom_killed)) {
        raise(item.component, *v, false);
      } else {
        events.Write(ExitedEventJson(wall(), item.component, state->exit_code));
        say(item.component + " exited with code " + std::to_string(state->exit_code) + " (the trial goes on)");
      }
      return;
    }
    const std::string why = item.text.empty() ? "ended while the container runs" : item.text;
    raise(item.component, Verdict::Err("log stream of " + item.component + " broke: " + why), true);
  };
  auto start_monitor = [&]() -> Verdict {
    auto m = Monitor::Create(*tree);
    if (!m) return Verdict::FromError(m.error(), "end conditions");
    monitor.emplace(std::move(*m));
    for (dsl::Plugin* p : tree->Plugins()) {
      monitor->Started(p->id());
      // A brain may go (its drone's offboard failsafe answers, in the agent's events); a user's
      // component may finish its job (exit 0). Anything else leaving is a crash.
      const auto role = p->spec().labels.find(std::string(kLabelRole));
      if (role == p->spec().labels.end()) continue;
      if (role->second == kRoleBrain) monitor->SetExitRule(p->id(), Monitor::ExitRule::kAnyExitAllowed);
      if (role->second == kRoleComponent) monitor->SetExitRule(p->id(), Monitor::ExitRule::kCleanExitAllowed);
    }
    return Verdict::Success();
  };

  if (start.ok()) start = start_monitor();
  if (start.ok()) start = start_faults();
  if (start.ok()) {
    double next_progress = 0;
    while (true) {
      for (const HubItem& item : hub.Drain(o.poll)) process(item);
      rtf.Observe(wall(), monitor->sim_s());
      if (auto v = monitor->OnTick(wall())) tree->RaiseShutdown(*v);
      if (injector && !tree->end_verdict()) {
        if (auto v = injector->Advance()) tree->RaiseShutdown(*v);
        resume_logs();
      }
      if (o.interrupted != nullptr && o.interrupted->load()) {
        tree->RaiseShutdown(Verdict::Err(
            o.interrupt_reason ? o.interrupt_reason() : std::string("interrupted (Ctrl-C)"), "user"));
      }
      if (tree->restart_requested() && !tree->end_verdict()) {
        if (tree->restarts() < o.max_restarts) {
          say("restarting: " + tree->restart_reason());
          events.Write(LifecycleEventJson(wall(), "restart", tree->id(),
                                          Verdict::Err(tree->restart_reason())));
          if (injector) (void)injector->RemoveActive();
          bind_faults();
          counts = StartProgress(tree->Plugins().size());
          Verdict rv = tree->Restart(*engine);
          if (rv.ok()) rv = start_monitor();
          if (rv.ok()) rv = start_faults();
          if (!rv.ok()) tree->RaiseShutdown(rv);
        } else {
          tree->RaiseShutdown(Verdict::Err("restart requested (" + tree->restart_reason() +
                                           ") with no restarts left"));
        }
      }
      if (tree->end_verdict()) break;
      if (wall() >= next_progress) {
        say(monitor->ProgressLine());
        next_progress = wall() + o.progress_every_s;
      }
    }
  }

  Verdict verdict = start.ok() ? *tree->end_verdict() : start;
  // A trial that ends badly during its start (or with drones given up at it) names the drones
  // that did not join, from the physics server's event=joining/joined lines.
  if (!verdict.ok()) {
    if (auto note = NotJoinedNote(joining)) verdict.reason += "; " + *note;
  }
  say("ending: " + verdict.ToString());
  events.Write(LifecycleEventJson(wall(), "shutdown", info.name, verdict));
  if (tree && engine) {
    // Faults first (unpause, restart what a fault stopped); radio rules, partitions and
    // network.mesh are not undone: they go with the sidecars' namespaces when the tree stops them
    // (fault_injector.hpp).
    if (injector) {
      (void)injector->RemoveActive();
      if (dynamic_cast<dsl::Step*>(tree->Find(kFaultsStepId)) == nullptr) (void)injector->Teardown();
    }
    const double stop_began_s = wall();
    Verdict stop = tree->Stop(*engine);
    stop.KeepWorse(engine->FinishStops());  // exit codes, artifacts, removals still under way
    if (counts.created() > 0) {
      result.timing.teardown_s = wall() - stop_began_s;
      char took[64];
      std::snprintf(took, sizeof took, " in %.1f s", *result.timing.teardown_s);
      say("stopped and removed " + std::to_string(counts.created()) + " containers" + took);
    }
    result.timing.containers = counts.total();
    result.timing.created_s = counts.all_created_s();
    result.timing.started_s = counts.all_started_s();
    if (!stop.ok()) {
      result.problems.push_back("teardown: " + stop.ToString());
      verdict.KeepWorse(stop);
    }
    for (const HubItem& item : hub.Drain(std::chrono::milliseconds(0))) process(item);
    if (injector) {
      for (const std::string& p : injector->problems()) result.problems.push_back("faults: " + p);
    }
    result.components = engine->Reports();
    for (const std::string& p : engine->problems()) result.problems.push_back(p);
    result.restarts = tree->restarts();
  }
  result.verdict = verdict;
  result.wall_s = wall();
  result.sim_s = monitor ? monitor->sim_s() : 0;
  result.ending_line = monitor ? monitor->ending_line() : std::string();
  // The metrics as results.csv and report.html compute them, from the files just written.
  result.metrics = report::ReadTrialMetrics(dir.string()).value_or(report::MetricValues{});
  result.provenance = TrialProvenance(api, tree.get(), injector.get(), info.rtf, rtf.Achieved());

  // trajectories.png from the collected truth.csv.
  if (engine && engine->artifacts().count("truth.csv") > 0) {
    std::ifstream in(engine->artifacts().at("truth.csv"), std::ios::binary);
    std::ostringstream csv;
    csv << in.rdbuf();
    auto tracks = ParseTruthCsv(csv.str());
    const bool derived = info.files.count(std::string(kDerivedWorldFile)) > 0;  // world_size_m
    const std::string world_file = derived ? (dir / kDerivedWorldFile).string() : info.world_file;
    auto world = world_file.empty() ? Result<WorldPicture>(WorldPicture{}) : LoadWorldPicture(world_file);
    if (!tracks) {
      result.problems.push_back("trajectories.png: " + tracks.error().ToString());
    } else if (!world) {
      result.problems.push_back("trajectories.png: " + world.error().ToString());
    } else if (Status s = DrawTrajectories(*tracks, *world, detections,
                                           (dir / "trajectories.png").string());
               !s) {
      result.problems.push_back("trajectories.png: " + s.error().ToString());
    }
  } else {
    result.problems.push_back("trajectories.png not drawn: no truth.csv was collected");
  }
  // plots.html: the trial's quantities over simulated time, from the same logs and truth.csv.
  {
    report::TrialPlotsPage page;
    page.title = (o.trial_id.empty() ? info.name : o.trial_id) + " (run " + run_id + ")";
    page.summary = verdict.ToString();
    page.has_trajectories = fs::exists(dir / "trajectories.png");
    if (auto written = report::WriteTrialPlots(dir.string(), page); !written) {
      result.problems.push_back("plots.html: " + written.error().ToString());
    }
  }

  SWARMBOX_TRY(WriteFile(dir / "result.json", ResultJson(result)));
  say("result: " + verdict.ToString() + " (" + (dir / "result.json").string() + ")");
  return RunOutcome{std::move(result), dir.string()};
}

Result<RunOutcome> RunTrialSpec(const dsl::TrialSpec& spec, docker::DockerApi& api, Clock& clock,
                                const RunOptions& options) {
  if (options.view && options.host != "local") {
    return Error(ErrorCode::kInvalidArgument, "--view publishes the live view on this machine; host '" + options.host +
                                                  "' is remote (run the trial on the local engine to watch it)");
  }
  const std::string trials_dir =
      fs::absolute(spec.trials_dir.empty() ? fs::path(".") : fs::path(spec.trials_dir))
          .lexically_normal()
          .string();
  TrialInfo info;
  info.name = spec.name;
  info.seed = spec.seed;
  info.rtf = spec.rtf;
  info.resolved_yaml = yaml::Emit(spec.document.is_null() ? dsl::ToDocument(spec) : spec.document);
  info.world_file = (fs::path(trials_dir) / spec.world).string();
  if (spec.HasWorldSize()) {  // the world every container reads, written into the trial folder
    std::ifstream in(info.world_file, std::ios::binary);
    if (!in) return Error(ErrorCode::kNotFound, "cannot read the world file", info.world_file);
    std::ostringstream text;
    text << in.rdbuf();
    auto derived = DeriveWorld(text.str(), info.world_file, spec.world_size_m);
    if (!derived) return derived.error().Context("world_size_m");
    info.files[std::string(kDerivedWorldFile)] = std::move(*derived);
  }
  if (auto payloads = LoadPayloadMasses(spec, trials_dir); !payloads) {
    return payloads.error().Context("checking payloads");
  }
  for (const dsl::DroneSpec& d : spec.drones) info.drones.push_back(d.name);
  info.middleware = spec.middleware;
  info.radio_model = std::string(dsl::RadioModelName(spec.radio.model));
  const bool channel = spec.radio.model == dsl::RadioModel::kChannel;
  if (channel) {
    // The simulated radio: network.mesh and the faults at simulated times go to the physics
    // server in the radio plan; the rest (on:, at_wall:) stay with the fault injector.
    info.radio_profile = spec.radio.profile;
    SWARMBOX_TRY(CheckRadioProfile(spec, trials_dir));
    auto plan = PlanRadioSchedule(spec);
    if (!plan) return plan.error().Context("the radio plan");
    info.files[std::string(kRadioPlanFile)] = RadioScheduleJson(*plan) + "\n";
    for (const faults::Fault& f : spec.faults) (InRadioSchedule(f) ? info.planned_faults : info.faults).push_back(f);
  } else {
    info.mesh = spec.mesh;
    info.faults = spec.faults;
  }
  std::string faults_image = options.faults_image;
  if (NeedsFaultSidecars(spec) && faults_image.empty()) {
    auto netemd = FindNetemd(options.netemd_bin);
    if (!netemd) return netemd.error().Context("the fault sidecar image");
    auto tag = EnsureFaultsImage(api, *netemd, [&](std::string_view line) {
      if (options.progress != nullptr) *options.progress << "  " << line << std::endl;
    });
    if (!tag) return tag.error();
    faults_image = *tag;
  }
  // The images of the trial's own software that the caller did not bring.
  Images images = options.images;
  bool missing = false;
  for (const dsl::DroneSpec& d : spec.drones) {
    missing = missing || (d.brain.kind == dsl::BrainKind::kLibrary && images.drone_agents.count(d.name) == 0) ||
              (d.brain.external() && images.brains.count(d.name) == 0);
  }
  for (const dsl::UserComponentSpec& c : spec.components) missing = missing || images.components.count(c.name) == 0;
  if (missing) {
    const images::TagCache cache(images::DefaultTagCacheDir());
    auto made = EnsureUserImages(api, spec, options.agent_binary, images, [&](std::string_view line) {
      if (options.progress != nullptr) *options.progress << "  " << line << std::endl;
    }, &cache);
    if (!made) return made.error();
    images = std::move(*made);
  }
  Planner planner = [&, faults_image, channel, images](const std::string& run_id, const TrialSubnets& subnets) {
    PlanOptions p;
    if (channel) {  // RunTrial wrote it (info.files) into the trial folder
      p.radio_plan_path =
          (fs::absolute(options.out_dir) / TrialDirName(spec.name, run_id) / kRadioPlanFile).lexically_normal().string();
    }
    if (spec.HasWorldSize()) {  // RunTrial wrote it (info.files) into the trial folder
      p.world_path =
          (fs::absolute(options.out_dir) / TrialDirName(spec.name, run_id) / kDerivedWorldFile).lexically_normal().string();
    }
    p.run_id = run_id;
    p.trial_id = options.trial_id;
    p.images = images;
    p.faults_image = faults_image;
    p.subnets = subnets;
    p.trials_dir = trials_dir;
    p.view = options.view;
    return PlanTrial(spec, p);
  };
  return RunTrial(info, planner, api, clock, options);
}

}  // namespace swarmbox::runner
