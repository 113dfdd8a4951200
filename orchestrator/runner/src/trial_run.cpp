#include "trial_run.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/report/trial_record.hpp"
#include "swarmbox/runner/derived_world.hpp"
#include "swarmbox/runner/naming.hpp"
#include "swarmbox/runner/plan.hpp"

namespace swarmbox::runner::detail {

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

// ---- EventsFile ----

EventsFile::~EventsFile() {
  if (file_ != nullptr) std::fclose(file_);
}

Status EventsFile::Open(const fs::path& path) {
  if (file_ != nullptr) std::fclose(file_);
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) return Error(ErrorCode::kIo, "cannot write events.jsonl", path.parent_path().string());
  return Ok{};
}

void EventsFile::Write(const std::string& line) {
  if (file_ == nullptr) return;
  std::fwrite(line.data(), 1, line.size(), file_);
  std::fputc('\n', file_);
  std::fflush(file_);
}

// ---- The driver ----

TrialRun::TrialRun(const TrialInfo& info, const Planner& planner, docker::DockerApi& api, Clock& clock,
                   const RunOptions& options)
    : info_(info),
      planner_(planner),
      api_(api),
      clock_(clock),
      options_(options),
      run_id_(options.run_id.empty() ? NewRunId() : options.run_id),
      trial_id_(options.trial_id.empty() ? info.name : options.trial_id),
      dir_(fs::path(options.out_dir) / TrialDirName(info.name, run_id_)),
      has_faults_(!info.mesh.empty() || !info.faults.empty() || !info.planned_faults.empty()) {
  result_.trial = info.name;
  result_.trial_id = trial_id_;
  result_.run_id = run_id_;
  result_.seed = info.seed;
  result_.host = options.host;
  result_.radio_model = info.radio_model;
  result_.radio_profile = info.radio_profile;
}

Result<RunOutcome> TrialRun::Run() {
  SWARMBOX_TRY(PrepareFolder());
  RefreshTakenSubnets();
  t0_s_ = clock_.NowS();
  Say("run " + run_id_ + " -> " + dir_.string());
  auto started = StartWithSubnetRetry();
  if (!started) return started.error();
  Verdict start = *started;
  if (start.ok()) start = StartWatching();
  if (start.ok()) Watch();
  Verdict verdict = start.ok() ? *tree_->end_verdict() : start;
  // A trial that ends badly during its start (or with drones given up at it) names the drones
  // that did not join, from the physics server's event=joining/joined lines.
  if (!verdict.ok()) {
    if (auto note = NotJoinedNote(joining_)) verdict.reason += "; " + *note;
  }
  ShutDown(verdict);
  return WriteResult(verdict);
}

double TrialRun::Wall() const { return clock_.NowS() - t0_s_; }

void TrialRun::Say(const std::string& line) const {
  if (options_.progress != nullptr) *options_.progress << "[" << info_.name << "] " << line << std::endl;
}

// ---- Phase: the folder ----

Status TrialRun::PrepareFolder() {
  std::error_code ec;
  fs::create_directories(dir_ / "logs", ec);
  if (ec) return Error(ErrorCode::kIo, "cannot create the trial folder: " + ec.message(), dir_.string());
  SWARMBOX_TRY(WriteFile(dir_ / "trial.yaml", info_.resolved_yaml));
  for (const auto& [file, text] : info_.files) SWARMBOX_TRY(WriteFile(dir_ / file, text));
  SWARMBOX_TRY(events_.Open(dir_ / "events.jsonl"));
  if (auto warning = RadioRtfWarning(info_.radio_model, info_.rtf)) events_.Write(WarningEventJson(0.0, *warning));
  if (auto ping = api_.Ping(); !ping) return ping.error().Context("reaching the Docker engine");
  return Ok{};
}

// ---- Phase: start, with another pair of subnets after a conflict ----

Result<Verdict> TrialRun::StartWithSubnetRetry() {
  Verdict start;
  for (int attempt = 0; attempt < std::max(1, options_.subnet_attempts); ++attempt) {
    // Keyed by run and trial: an experiment's parallel trials share the run id and would all
    // start from the same pair, racing for it.
    auto subnets = PickSubnets(run_id_ + "/" + trial_id_, attempt, taken_subnets_);
    if (!subnets) {
      start = Verdict::FromError(subnets.error(), "subnets");
      break;
    }
    auto planned = planner_(run_id_, *subnets);
    if (!planned) return planned.error().Context("planning the trial");
    AdoptTree(std::move(*planned));
    engine_ = std::make_unique<DockerEngine>(api_, hub_, clock_, MakeEngineOptions());
    BindFaults();
    start = tree_->Start(*engine_);
    if (start.ok() || !engine_->subnet_conflict()) break;
    Say("subnet conflict (" + start.reason + "), trying another pair");
    (void)tree_->Stop(*engine_);
    engine_.reset();
    DropTree();
    RefreshTakenSubnets();
  }
  // After a failed start, creations queued ahead may still trace their build: let them finish
  // before the runner writes to events.jsonl itself.
  if (engine_) engine_->FinishCreates();
  return start;
}

void TrialRun::RefreshTakenSubnets() {
  taken_subnets_.clear();
  if (auto nets = api_.ListNetworks({})) {
    for (const auto& n : *nets) {
      if (!n.subnet.empty()) taken_subnets_.push_back(n.subnet);
    }
  }
}

EngineOptions TrialRun::MakeEngineOptions() {
  EngineOptions eo;
  eo.trial_dir = dir_.string();
  eo.start_wall_s = t0_s_;
  eo.interrupted = options_.interrupted;
  eo.max_parallel = options_.max_parallel > 0 ? options_.max_parallel : ParallelFromEnvironment(eo.max_parallel);
  eo.on_trace = [this](const dsl::Component& c, dsl::EventKind e, const Verdict& v) { OnTrace(c, e, v); };
  return eo;
}

// events.jsonl gets every step; the terminal a failed step, and counts of created and started
// containers.
void TrialRun::OnTrace(const dsl::Component& c, dsl::EventKind e, const Verdict& v) {
  events_.Write(LifecycleEventJson(Wall(), dsl::EventName(e), c.id(), v));
  if (!v.ok()) {
    Say(std::string(dsl::EventName(e)) + " " + c.id() + ": " + v.ToString());
    return;
  }
  if (dynamic_cast<const dsl::Plugin*>(&c) == nullptr) return;
  std::optional<std::string> line;
  if (e == dsl::EventKind::kBuild) line = counts_.OnCreated(Wall());
  if (e == dsl::EventKind::kRun) line = counts_.OnStarted(Wall());
  if (line) Say(*line);
}

void TrialRun::AdoptTree(std::unique_ptr<dsl::Trial> tree) {
  tree_ = std::move(tree);
  faults_step_ = dynamic_cast<dsl::Step*>(tree_->Find(kFaultsStepId));
  counts_ = StartProgress(tree_->Plugins().size());
}

void TrialRun::DropTree() {
  faults_step_ = nullptr;
  tree_.reset();
}

// ---- Phase: watching begins ----

Verdict TrialRun::StartWatching() {
  Verdict v = StartMonitor();
  if (v.ok()) v = StartFaults();
  return v;
}

Verdict TrialRun::StartMonitor() {
  auto m = Monitor::Create(*tree_);
  if (!m) return Verdict::FromError(m.error(), "end conditions");
  monitor_.emplace(std::move(*m));
  for (dsl::Plugin* p : tree_->Plugins()) {
    monitor_->Started(p->id());
    // A brain may go (its drone's offboard failsafe answers, in the agent's events); a user's
    // component may finish its job (exit 0). Anything else leaving is a crash.
    const auto role = p->spec().labels.find(std::string(kLabelRole));
    if (role == p->spec().labels.end()) continue;
    if (role->second == kRoleBrain) monitor_->SetExitRule(p->id(), Monitor::ExitRule::kAnyExitAllowed);
    if (role->second == kRoleComponent) monitor_->SetExitRule(p->id(), Monitor::ExitRule::kCleanExitAllowed);
  }
  return Verdict::Success();
}

// ---- Faults: one injector per started tree ----

std::unique_ptr<FaultInjector> TrialRun::MakeInjector() {
  InjectorConfig c;
  c.drones = info_.drones;
  c.mesh = info_.mesh;
  c.faults = info_.faults;
  c.planned = info_.planned_faults;
  c.physics_component = std::string(kPhysicsId);
  c.seed = info_.seed;
  c.host = options_.host;
  for (const std::string& d : info_.drones) {
    if (dsl::Plugin* agent = tree_->FindPlugin(d)) c.agents[d] = agent->spec().name;
    if (dsl::Plugin* sidecar = tree_->FindPlugin(SidecarId(d))) {
      c.sidecars[d] = sidecar->spec().name;
      for (const dsl::Attachment& a : sidecar->spec().networks) {
        if (a.network == kMeshNetworkId) c.mesh_ipv4[d] = a.ipv4;
      }
    }
  }
  c.mesh_interface = std::string(kMeshInterfaceName);
  if (dsl::Plugin* physics = tree_->FindPlugin(kPhysicsId)) c.physics_container = physics->spec().name;
  c.physics_command_argv = [middleware = info_.middleware](const faults::WorldCommandCall& call) {
    return PhysicsCommandArgv(middleware, call);
  };
  return std::make_unique<FaultInjector>(
      api_, std::move(c), [this](const std::string& line) { events_.Write(line); },
      [this] { return monitor_ ? monitor_->sim_s() : 0.0; }, [this] { return Wall(); });
}

Verdict TrialRun::SetUpFaults() {
  injector_ = MakeInjector();
  return injector_->Setup();
}

// With sidecars the tree's `faults` Step runs the set-up between the sidecars and the agents;
// without (process faults only) StartFaults runs it once the tree has started.
void TrialRun::BindFaults() {
  if (!has_faults_ || faults_step_ == nullptr) return;
  faults_step_->Bind([this] { return SetUpFaults(); },
                     [this] { return injector_ ? injector_->Teardown() : Verdict::Success(); });
}

Verdict TrialRun::StartFaults() {
  if (!has_faults_ || faults_step_ != nullptr) return Verdict::Success();
  return SetUpFaults();
}

void TrialRun::AdvanceFaults() {
  if (!injector_ || tree_->end_verdict()) return;
  if (auto v = injector_->Advance()) tree_->RaiseShutdown(*v);
  ResumeLogs();
}

void TrialRun::ResumeLogs() {
  if (!injector_ || !engine_) return;
  for (const std::string& c : injector_->TakeResumed()) {
    if (Status s = engine_->ResumeLogs(c); !s) {
      tree_->RaiseShutdown(Verdict::FromError(s.error().Context("following " + c + " again"), c));
    } else if (monitor_) {
      monitor_->Started(c);
    }
  }
}

// ---- Phase: watch ----

void TrialRun::Watch() {
  double next_progress_s = 0;
  while (true) {
    for (const HubItem& item : hub_.Drain(options_.poll)) HandleHubItem(item);
    rtf_.Observe(Wall(), monitor_->sim_s());
    if (auto v = monitor_->OnTick(Wall())) tree_->RaiseShutdown(*v);
    AdvanceFaults();
    if (options_.interrupted != nullptr && options_.interrupted->load()) {
      tree_->RaiseShutdown(Verdict::Err(
          options_.interrupt_reason ? options_.interrupt_reason() : std::string("interrupted (Ctrl-C)"), "user"));
    }
    if (tree_->restart_requested() && !tree_->end_verdict()) Restart();
    if (tree_->end_verdict()) return;
    if (Wall() >= next_progress_s) {
      Say(monitor_->ProgressLine());
      next_progress_s = Wall() + options_.progress_every_s;
    }
  }
}

void TrialRun::HandleHubItem(const HubItem& item) {
  if (item.kind == HubItem::Kind::kLine) {
    HandleLogLine(item);
  } else {
    HandleStreamEnd(item);
  }
}

void TrialRun::HandleLogLine(const HubItem& item) {
  const LogfmtFields fields = ParseLogfmt(item.text);
  if (auto j = LogEventJson(item.wall_s, item.component, fields)) {
    events_.Write(*j);
    RecordDetection(item, fields);
  }
  if (monitor_ && tree_) {
    if (auto v = monitor_->OnLine(item.component, item.text)) Raise(item.component, *v, false);
  }
  FoldJoining(item, fields);
  if (injector_ && tree_ && !tree_->end_verdict()) {
    // The line may move simulated time on: `at:` faults fire at the line that crosses.
    if (auto v = injector_->OnLogLine(item.component, item.text)) tree_->RaiseShutdown(*v);
    if (auto v = injector_->Advance(); v && !tree_->end_verdict()) tree_->RaiseShutdown(*v);
    ResumeLogs();
  }
}

void TrialRun::RecordDetection(const HubItem& item, const LogfmtFields& fields) {
  auto ev = FindField(fields, "event");
  if (!ev || (*ev != "victim_detected" && *ev != "victim_confirmed")) return;
  auto x = NumberField(fields, {"x", "x_m"});
  auto y = NumberField(fields, {"y", "y_m"});
  if (x && y) {
    detections_.push_back({FindField(fields, "node").value_or(item.component), *x, *y, *ev == "victim_confirmed"});
  }
}

// The physics server's start, folded apart from the monitor (which stops at the trial's end: the
// lines of the start may come after another stream's ending line).
void TrialRun::FoldJoining(const HubItem& item, const LogfmtFields& fields) {
  auto ev = FindField(fields, "event");
  if (!ev || (*ev != "joining" && *ev != "joined")) return;
  joining_.OnLine(item.component, item.text);
  if (result_.timing.joined_s) return;
  if (auto line = JoinedLine(joining_)) {
    Say(*line);
    result_.timing.joined_s = item.wall_s;
  }
}

// The end of a log stream: the container stopped, or the stream broke.
void TrialRun::HandleStreamEnd(const HubItem& item) {
  if (!engine_ || !engine_->IsCurrent(item) || !monitor_ || !tree_ || tree_->end_verdict()) return;
  // A container a fault took down (kill, stop, restart) did not crash.
  if (injector_ && injector_->Disrupted(item.component)) return;
  auto state = engine_->Inspect(item.component);
  if (state && !state->running) {
    if (auto v = monitor_->OnExit(item.component, state->exit_code, state->oom_killed)) {
      Raise(item.component, *v, false);
    } else {
      events_.Write(ExitedEventJson(Wall(), item.component, state->exit_code));
      Say(item.component + " exited with code " + std::to_string(state->exit_code) + " (the trial goes on)");
    }
    return;
  }
  const std::string why = item.text.empty() ? "ended while the container runs" : item.text;
  Raise(item.component, Verdict::Err("log stream of " + item.component + " broke: " + why), true);
}

void TrialRun::Raise(const std::string& component, Verdict verdict, bool restart) {
  dsl::Component* c = tree_->Find(component);
  if (c == nullptr) c = tree_.get();
  if (restart) {
    c->RaiseRestart(verdict.reason);
  } else {
    c->RaiseShutdown(std::move(verdict));
  }
}

// ---- Phase: restart ----

void TrialRun::Restart() {
  if (tree_->restarts() >= options_.max_restarts) {
    tree_->RaiseShutdown(Verdict::Err("restart requested (" + tree_->restart_reason() + ") with no restarts left"));
    return;
  }
  Say("restarting: " + tree_->restart_reason());
  events_.Write(LifecycleEventJson(Wall(), "restart", tree_->id(), Verdict::Err(tree_->restart_reason())));
  if (injector_) (void)injector_->RemoveActive();
  BindFaults();
  counts_ = StartProgress(tree_->Plugins().size());
  Verdict v = tree_->Restart(*engine_);
  if (v.ok()) v = StartWatching();
  if (!v.ok()) tree_->RaiseShutdown(v);
}

// ---- Phase: shut down ----

void TrialRun::ShutDown(Verdict& verdict) {
  Say("ending: " + verdict.ToString());
  events_.Write(LifecycleEventJson(Wall(), "shutdown", info_.name, verdict));
  if (!tree_ || !engine_) return;
  // Faults first (unpause, restart what a fault stopped); radio rules, partitions and
  // network.mesh are not undone: they go with the sidecars' namespaces when the tree stops them
  // (fault_injector.hpp).
  if (injector_) {
    (void)injector_->RemoveActive();
    if (faults_step_ == nullptr) (void)injector_->Teardown();
  }
  const double stop_began_s = Wall();
  Verdict stop = tree_->Stop(*engine_);
  stop.KeepWorse(engine_->FinishStops());  // exit codes, artifacts, removals still under way
  CollectTeardown(stop_began_s, stop, verdict);
  for (const HubItem& item : hub_.Drain(std::chrono::milliseconds(0))) HandleHubItem(item);
  if (injector_) {
    for (const std::string& p : injector_->problems()) result_.problems.push_back("faults: " + p);
  }
  result_.components = engine_->Reports();
  for (const std::string& p : engine_->problems()) result_.problems.push_back(p);
  result_.restarts = tree_->restarts();
}

void TrialRun::CollectTeardown(double stop_began_s, const Verdict& stop, Verdict& verdict) {
  if (counts_.created() > 0) {
    result_.timing.teardown_s = Wall() - stop_began_s;
    char took[64];
    std::snprintf(took, sizeof took, " in %.1f s", *result_.timing.teardown_s);
    Say("stopped and removed " + std::to_string(counts_.created()) + " containers" + took);
  }
  result_.timing.containers = counts_.total();
  result_.timing.created_s = counts_.all_created_s();
  result_.timing.started_s = counts_.all_started_s();
  if (!stop.ok()) {
    result_.problems.push_back("teardown: " + stop.ToString());
    verdict.KeepWorse(stop);
  }
}

// ---- Phase: the result ----

Result<RunOutcome> TrialRun::WriteResult(const Verdict& verdict) {
  result_.verdict = verdict;
  result_.wall_s = Wall();
  result_.sim_s = monitor_ ? monitor_->sim_s() : 0;
  result_.ending_line = monitor_ ? monitor_->ending_line() : std::string();
  // The metrics as results.csv and report.html compute them, from the files just written.
  result_.metrics = report::ReadTrialMetrics(dir_.string()).value_or(report::MetricValues{});
  result_.provenance = TrialProvenance(api_, tree_.get(), injector_.get(), info_.rtf, rtf_.Achieved());
  DrawTrajectoriesPicture();
  WritePlotsPage(verdict);
  SWARMBOX_TRY(WriteFile(dir_ / "result.json", ResultJson(result_)));
  Say("result: " + verdict.ToString() + " (" + (dir_ / "result.json").string() + ")");
  return RunOutcome{std::move(result_), dir_.string()};
}

// trajectories.png from the collected truth.csv.
void TrialRun::DrawTrajectoriesPicture() {
  if (!engine_ || engine_->artifacts().count("truth.csv") == 0) {
    result_.problems.push_back("trajectories.png not drawn: no truth.csv was collected");
    return;
  }
  std::ifstream in(engine_->artifacts().at("truth.csv"), std::ios::binary);
  std::ostringstream csv;
  csv << in.rdbuf();
  auto tracks = ParseTruthCsv(csv.str());
  const bool derived = info_.files.count(std::string(kDerivedWorldFile)) > 0;  // world_size_m, generated
  const std::string world_file = derived ? (dir_ / kDerivedWorldFile).string() : info_.world_file;
  auto world = world_file.empty() ? Result<WorldPicture>(WorldPicture{}) : LoadWorldPicture(world_file);
  if (!tracks) {
    result_.problems.push_back("trajectories.png: " + tracks.error().ToString());
  } else if (!world) {
    result_.problems.push_back("trajectories.png: " + world.error().ToString());
  } else if (Status s = DrawTrajectories(*tracks, *world, detections_, (dir_ / "trajectories.png").string()); !s) {
    result_.problems.push_back("trajectories.png: " + s.error().ToString());
  }
}

// plots.html: the trial's quantities over simulated time, from the same logs and truth.csv.
void TrialRun::WritePlotsPage(const Verdict& verdict) {
  report::TrialPlotsPage page;
  page.title = trial_id_ + " (run " + run_id_ + ")";
  page.summary = verdict.ToString();
  page.has_trajectories = fs::exists(dir_ / "trajectories.png");
  if (auto written = report::WriteTrialPlots(dir_.string(), page); !written) {
    result_.problems.push_back("plots.html: " + written.error().ToString());
  }
}

}  // namespace swarmbox::runner::detail
