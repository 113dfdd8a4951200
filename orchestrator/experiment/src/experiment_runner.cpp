#include "swarmbox/experiment/experiment_runner.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/dsl/trial_loader.hpp"
#include "swarmbox/experiment/background_removal.hpp"
#include "swarmbox/experiment/progress.hpp"
#include "swarmbox/experiment/trial_store.hpp"
#include "swarmbox/report/report_html.hpp"
#include "swarmbox/report/results_csv.hpp"
#include "swarmbox/report/trial_record.hpp"
#include "swarmbox/runner/fault_image.hpp"
#include "swarmbox/runner/plan.hpp"

namespace swarmbox::experiment {

namespace fs = std::filesystem;
using yaml::Node;

namespace {

Node Str(std::string_view s) { return Node::Scalar(std::string(s), {}, /*quoted=*/true); }

std::vector<std::string> FactorNamesOf(const ExperimentSpec& spec) {
  std::vector<std::string> names;
  for (const Factor& f : spec.factors) names.push_back(f.name);
  return names;
}

report::TrialMeta MetaOf(const ExperimentSpec& spec, const PlannedTrial& t, int attempts,
                         std::vector<std::string> hosts) {
  report::TrialMeta m;
  m.id = t.id;
  m.code = t.code;
  m.factors = FactorNamesOf(spec);
  m.levels = t.levels;
  m.repetition = t.repetition;
  m.seed = t.seed;
  m.attempts = attempts;
  m.hosts = std::move(hosts);
  return m;
}

// Shared state of one RunExperiment: the attempt history and the one monotonic clock.
struct Session {
  const ExperimentPlan* plan = nullptr;
  const ExperimentOptions* options = nullptr;
  TrialStore* store = nullptr;
  std::mutex mu;
  std::map<std::string, std::vector<std::string>> hosts_of;  // trial -> host per attempt
  runner::SteadyClock clock;

  void AttemptOn(const std::string& trial, const std::string& host) {
    std::lock_guard lock(mu);
    hosts_of[trial].push_back(host);
  }
  std::vector<std::string> HostsOf(const std::string& trial) {
    std::lock_guard lock(mu);
    return hosts_of[trial];
  }
};

// Writes a result.json of outcome error for a trial that never produced one, and commits it.
Status CommitError(Session& s, const PlannedTrial& t, int attempts, const std::string& host,
                   const std::string& reason) {
  auto staging = s.store->Staging(t.id, 0);
  if (!staging) return staging.error();
  runner::TrialResult r;
  r.trial = t.id;
  r.trial_id = t.id;
  r.run_id = s.options->run_id;
  r.verdict = dsl::Verdict::Err(reason, "experiment");
  r.seed = t.seed;
  r.host = host;
  const fs::path dir(*staging);
  const dsl::TrialSpec& spec = s.plan->specs.at(t.id);
  SWARMBOX_TRY(WriteFileAtomic((dir / "trial.yaml").string(),
                               yaml::Emit(spec.document.is_null() ? dsl::ToDocument(spec)
                                                                  : spec.document)));
  SWARMBOX_TRY(WriteFileAtomic(
      (dir / "trial_meta.json").string(),
      report::TrialMetaJson(MetaOf(s.plan->spec, t, attempts, s.HostsOf(t.id)))));
  SWARMBOX_TRY(WriteFileAtomic((dir / "result.json").string(), runner::ResultJson(r)));
  return s.store->Commit(t.id, *staging);
}

class TrialExecutor final : public HostWorker {
 public:
  // remover: the host's background remover, or nullptr to remove inside each trial.
  TrialExecutor(Session& session, const PoolHost& host, BackgroundRemover* remover)
      : s_(session), host_(host), remover_(remover) {}
  std::string name() const override { return host_.name; }
  int slots() const override { return host_.slots; }

  AttemptResult Run(const PlannedTrial& t, int attempt) override {
    s_.AttemptOn(t.id, host_.name);
    auto staging = s_.store->Staging(t.id, attempt);
    if (!staging) return Lost("cannot make the staging folder: " + staging.error().ToString());
    std::ofstream log(fs::path(*staging) / "orchestrator.log");
    const runner::RunOptions o = OptionsFor(t, *staging, &log);
    // With a remover, the trial's containers and networks are removed while this slot goes on
    // (background_removal.hpp): the attempt ends once result.json, the logs and truth.csv are in.
    std::optional<DeferredRemovalApi> deferred;
    if (remover_ != nullptr) deferred.emplace(*host_.api, *remover_);
    docker::DockerApi& api = deferred ? static_cast<docker::DockerApi&>(*deferred) : *host_.api;
    auto run = runner::RunTrialSpec(s_.plan->specs.at(t.id), api, s_.clock, o);
    log.close();
    const ExperimentOptions& eo = *s_.options;
    const bool interrupted = eo.interrupted != nullptr && eo.interrupted->load();
    if (interrupted) {
      return {AttemptResult::Kind::kCancelled, "", "interrupted (Ctrl-C)"};
    }
    if (!run) return CouldNotStart(t, attempt, *staging, run.error());
    return CommitRun(t, attempt, *staging, *run);
  }

 private:
  // The experiment's trial options for this attempt on this host, its progress into `log`.
  runner::RunOptions OptionsFor(const PlannedTrial& t, const std::string& staging, std::ostream* log) const {
    const ExperimentOptions& eo = *s_.options;
    runner::RunOptions o = eo.trial_options;
    o.out_dir = staging;
    o.run_id = eo.run_id;
    o.trial_id = t.id;
    o.host = host_.name;
    o.images = host_.images;
    if (!host_.faults_image.empty()) o.faults_image = host_.faults_image;
    o.interrupted = eo.interrupted;
    o.progress = log;
    return o;
  }

  // The trial did not start: the host's fault when it no longer answers, else the trial's outcome
  // error (committed).
  AttemptResult CouldNotStart(const PlannedTrial& t, int attempt, const std::string& staging, const Error& error) {
    if (Status h = host_.check(); !h) return Lost(h.error().message(), staging, t.id, attempt);
    // The host answers but the trial could not start (not the host's fault): an outcome.
    const std::string reason = "could not start: " + error.ToString();
    if (Status c = CommitError(s_, t, attempt, host_.name, reason); !c) {
      return Lost("cannot record the trial: " + c.error().ToString());
    }
    return {AttemptResult::Kind::kCompleted, "error", reason};
  }

  // The trial ran: an outcome error from a host that no longer answers is the host's; else its
  // folder gets the orchestrator log and trial_meta.json and is committed.
  AttemptResult CommitRun(const PlannedTrial& t, int attempt, const std::string& staging,
                          const runner::RunOutcome& run) {
    const runner::TrialResult& r = run.result;
    if (r.verdict.outcome == dsl::Outcome::kError) {
      if (Status h = host_.check(); !h) {
        return Lost(h.error().message() + " (trial: " + r.verdict.reason + ")", run.trial_dir, t.id, attempt);
      }
    }
    std::error_code ec;
    fs::rename(fs::path(staging) / "orchestrator.log", fs::path(run.trial_dir) / "orchestrator.log", ec);
    Status meta = WriteFileAtomic((fs::path(run.trial_dir) / "trial_meta.json").string(),
                                  report::TrialMetaJson(MetaOf(s_.plan->spec, t, attempt, s_.HostsOf(t.id))));
    if (!meta) return Lost("cannot write trial_meta.json: " + meta.error().ToString());
    if (Status c = s_.store->Commit(t.id, run.trial_dir); !c) {
      return Lost("cannot commit the trial: " + c.error().ToString());
    }
    fs::remove_all(staging, ec);
    return {AttemptResult::Kind::kCompleted, std::string(dsl::OutcomeName(r.verdict.outcome)), r.verdict.reason};
  }

  AttemptResult Lost(std::string reason, const std::string& dir = {}, const std::string& id = {},
                     int attempt = 0) {
    if (!dir.empty()) (void)s_.store->Discard(id, attempt, dir);
    return {AttemptResult::Kind::kHostFailed, "", std::move(reason)};
  }

  Session& s_;
  const PoolHost& host_;
  BackgroundRemover* remover_;
};

// Updates the board and prints it; records exhausted trials.
class Observer final : public ScheduleObserver {
 public:
  Observer(Session& s, ProgressBoard& board, std::mutex& board_mu, std::vector<std::string>& problems)
      : s_(s), board_(board), board_mu_(board_mu), problems_(problems) {}

  void OnStart(const std::string& host, const PlannedTrial& t, int /*attempt*/) override {
    std::lock_guard lock(board_mu_);
    board_.Started(host, t.id, s_.clock.NowS());
  }
  void OnFinish(const std::string& host, const PlannedTrial& t, const AttemptResult& r) override {
    std::lock_guard lock(board_mu_);
    board_.Finished(host, t.id, r.kind == AttemptResult::Kind::kCompleted ? r.outcome : "",
                    s_.clock.NowS());
  }
  void OnHostDown(const std::string& host, const std::string& reason) override {
    {
      std::lock_guard lock(board_mu_);
      board_.HostDown(host, reason);
    }
    problems_.push_back("host " + host + " left the pool: " + reason);
    if (s_.options->progress != nullptr) {
      *s_.options->progress << "swarmbox experiment: host " << host << " left the pool: " << reason
                            << "\n";
    }
  }
  void OnExhausted(const PlannedTrial& t, const std::string& reason) override {
    const auto hosts = s_.HostsOf(t.id);
    if (Status c = CommitError(s_, t, static_cast<int>(hosts.size()),
                               hosts.empty() ? "" : hosts.back(), reason);
        !c) {
      problems_.push_back("cannot record " + t.id + ": " + c.error().ToString());
    }
    std::lock_guard lock(board_mu_);
    board_.Exhausted(t.id);
  }

 private:
  Session& s_;
  ProgressBoard& board_;
  std::mutex& board_mu_;
  std::vector<std::string>& problems_;
};

}  // namespace

namespace {

// A pool host's name, images and engine (GET /version; empty when it does not answer).
Node HostProvenance(const PoolHost& h) {
  Node host = Node::Mapping();
  host.Set("name", Str(h.name));
  Node images = Node::Sequence();
  for (const std::string& image : {h.images.agent, h.images.physics, h.faults_image}) {
    if (!image.empty()) images.Append(Str(image));
  }
  host.Set("images", std::move(images));
  docker::EngineVersion engine;
  if (h.api != nullptr) {
    if (auto v = h.api->Version()) engine = *v;
  }
  host.Set("docker_version", Str(engine.version));
  host.Set("docker_api_version", Str(engine.api_version));
  host.Set("kernel", Str(engine.kernel_version));
  return host;
}

// From the trials run so far (their result.json): the fault mechanisms used, the rtf achieved.
void SetTrialsProvenance(const std::vector<report::Provenance>& trials, Node* prov) {
  std::set<std::string> mechanisms;
  std::optional<double> rtf_min, rtf_max;
  for (const report::Provenance& t : trials) {
    if (!t.fault_mechanism.empty()) mechanisms.insert(t.fault_mechanism);
    if (t.rtf_achieved) {
      rtf_min = rtf_min ? std::min(*rtf_min, *t.rtf_achieved) : *t.rtf_achieved;
      rtf_max = rtf_max ? std::max(*rtf_max, *t.rtf_achieved) : *t.rtf_achieved;
    }
  }
  Node used = Node::Sequence();
  for (const std::string& m : mechanisms) used.Append(Str(m));
  prov->Set("fault_mechanisms", std::move(used));
  auto number = [](const std::optional<double>& v) {
    return v ? Node::Scalar(report::CsvNumber(*v)) : Node::Null();
  };
  prov->Set("rtf_achieved_min", number(rtf_min));
  prov->Set("rtf_achieved_max", number(rtf_max));
}

// What every trial shares; each trial's result.json (and results.csv row) has its own engine,
// fault mechanism and rtf achieved.
Node ExperimentProvenance(const ExperimentPlan& plan, const std::vector<PoolHost>& pool,
                          const std::vector<report::Provenance>& trials) {
  const report::Provenance local = report::LocalProvenance();
  Node prov = Node::Mapping();
  prov.Set("swarmbox_version", Str(local.swarmbox_version));
  prov.Set("swarmbox_commit", Str(local.swarmbox_commit));
  prov.Set("build_type", Str(local.build_type));
  prov.Set("host_name", Str(local.host_name));
  std::set<double> rtfs;
  for (const auto& [id, spec] : plan.specs) rtfs.insert(spec.rtf);
  prov.Set("rtf_requested", rtfs.size() == 1 ? Node::Scalar(report::CsvNumber(*rtfs.begin())) : Node::Null());
  Node hosts = Node::Sequence();
  for (const PoolHost& h : pool) hosts.Append(HostProvenance(h));
  prov.Set("hosts", std::move(hosts));
  SetTrialsProvenance(trials, &prov);
  return prov;
}

}  // namespace

std::string ExperimentJson(const ExperimentPlan& plan, const std::vector<std::string>& run_ids,
                           const std::vector<PoolHost>& pool,
                           const std::vector<report::Provenance>& trials) {
  Node doc = Node::Mapping();
  doc.Set("name", Str(plan.spec.name));
  doc.Set("file", Str(plan.spec.file));
  doc.Set("base", Str(plan.spec.base_trial));
  Node factors = Node::Sequence();
  for (const Factor& f : plan.spec.factors) factors.Append(Str(f.name));
  doc.Set("factors", std::move(factors));
  doc.Set("trials", Node::Scalar(std::to_string(plan.trials.size())));
  Node ids = Node::Sequence();
  for (const std::string& id : run_ids) ids.Append(Str(id));
  doc.Set("run_ids", std::move(ids));
  doc.Set("provenance", ExperimentProvenance(plan, pool, trials));
  return yaml::EmitJson(doc) + "\n";
}

Result<ExperimentPlan> PlanExperiment(const ExperimentSpec& spec) {
  ExperimentPlan plan;
  plan.spec = spec;
  auto trials = ExpandTrials(spec);
  if (!trials) return trials.error();
  plan.trials = std::move(*trials);
  for (const PlannedTrial& t : plan.trials) {
    dsl::LoadOptions load;
    load.overrides = t.overrides;
    auto trial = dsl::LoadTrial(spec.base_trial, load);
    if (!trial) return trial.error().Context("trial " + t.id + " (code " + t.code + ")");
    plan.specs.emplace(t.id, std::move(*trial));
  }
  return plan;
}

Result<std::string> EnsurePlanFaultsImage(const ExperimentPlan& plan, docker::DockerApi& api,
                                          const std::function<void(std::string_view)>& progress) {
  const bool needed = std::any_of(plan.specs.begin(), plan.specs.end(), [](const auto& kv) {
    return runner::NeedsFaultSidecars(kv.second);
  });
  if (!needed) return std::string();
  auto netemd = runner::FindNetemd("");
  if (!netemd) return netemd.error().Context("the fault sidecar image");
  return runner::EnsureFaultsImage(api, *netemd, progress);
}

Result<std::size_t> WriteReports(const std::string& out_dir, std::vector<std::string>* problems) {
  auto records = report::ReadExperimentFolder(out_dir, problems);
  // Each trial's plots.html again from its logs and truth.csv (a folder without them keeps its own).
  for (report::TrialRecord& r : records) {
    report::TrialPlotsPage page;
    page.title = r.meta.id;
    page.summary = r.outcome + (r.reason.empty() ? "" : ": " + r.reason);
    page.has_trajectories = r.has_trajectories;
    auto written = report::WriteTrialPlots((fs::path(out_dir) / r.folder).string(), page);
    if (!written && problems != nullptr) problems->push_back(r.folder + "/plots.html: " + written.error().ToString());
    if (written && *written) r.has_plots = true;
  }
  const auto factors = report::FactorNames(out_dir, records);
  SWARMBOX_TRY(WriteFileAtomic((fs::path(out_dir) / "results.csv").string(),
                               report::ResultsCsv(factors, records)));
  SWARMBOX_TRY(WriteFileAtomic((fs::path(out_dir) / "report.html").string(),
                               report::ReportHtml("SwarmBox experiment " + report::ExperimentTitle(out_dir), factors, records)));
  // The page's box plots again as files, for documents that cannot hold inline SVG (a README).
  const fs::path plots_dir = fs::path(out_dir) / "plots";
  std::error_code ec;
  fs::create_directories(plots_dir, ec);
  if (ec) return Error(ErrorCode::kIo, "cannot create " + plots_dir.string() + ": " + ec.message());
  for (const report::ReportPlot& plot : report::ReportPlots(factors, records)) {
    SWARMBOX_TRY(WriteFileAtomic((plots_dir / report::PlotFileName(plot)).string(),
                                 report::StandalonePlotSvg(plot)));
  }
  return records.size();
}

Result<std::vector<std::string>> CheckOutFolder(const ExperimentPlan& plan, const std::string& out_dir,
                                               bool resume) {
  const fs::path meta_path = fs::path(out_dir) / "experiment.json";
  std::vector<std::string> run_ids;
  std::error_code ec;
  if (!fs::exists(meta_path, ec)) return run_ids;
  auto doc = yaml::ParseFile(meta_path.string());
  if (!doc || !doc->is_mapping()) {
    return Error(ErrorCode::kInvalidArgument, "cannot read experiment.json", meta_path.string());
  }
  const Node* name = doc->Find("name");
  if (name == nullptr || name->scalar() != plan.spec.name) {
    return Error(ErrorCode::kInvalidArgument,
                 "the folder holds another experiment ('" +
                     (name == nullptr ? std::string("?") : name->scalar()) +
                     "'): choose another --out",
                 out_dir);
  }
  if (const Node* ids = doc->Find("run_ids"); ids != nullptr && ids->is_sequence()) {
    for (const Node& id : ids->items()) run_ids.push_back(id.scalar());
  }
  TrialStore store(out_dir);
  const bool any_done = std::any_of(plan.trials.begin(), plan.trials.end(),
                                    [&](const PlannedTrial& t) { return store.Done(t.id); });
  if (any_done && !resume) {
    return Error(ErrorCode::kInvalidArgument,
                 "the folder already holds trials of this experiment: add --resume to run the "
                 "ones without result.json, or choose another --out",
                 out_dir);
  }
  return run_ids;
}

namespace {

// What a killed earlier run of this folder left on the hosts (its run ids).
void RemoveEarlierRuns(const std::vector<std::string>& run_ids, const std::vector<PoolHost>& pool,
                       std::vector<std::string>* problems) {
  for (const std::string& old : run_ids) {
    docker::LabelSelector sel;
    sel.equals[std::string(docker::kLabelRun)] = old;
    for (const PoolHost& h : pool) {
      if (auto removed = docker::RemoveLabelled(*h.api, sel, false);
          removed && !removed->containers.empty()) {
        problems->push_back("removed " + std::to_string(removed->containers.size()) +
                            " containers of the earlier run " + old + " on " + h.name);
      }
    }
  }
}

// The printer: redraws in place on a terminal, else prints the board every progress_every_s.
// Start() and Stop() from the experiment's thread; Stop() draws the board a last time.
class ProgressPrinter {
 public:
  ProgressPrinter(const ExperimentOptions& options, ProgressBoard& board, std::mutex& board_mu, runner::Clock& clock)
      : options_(options), board_(board), board_mu_(board_mu), clock_(clock) {}

  void Start() {
    if (options_.progress == nullptr) return;
    printer_ = std::thread([this] {
      const auto every = std::chrono::milliseconds(
          static_cast<long>((options_.progress_tty ? 1.0 : options_.progress_every_s) * 1000));
      std::unique_lock lock(stop_mu_);
      while (!stop_) {
        lock.unlock();
        Draw();
        lock.lock();
        stop_cv_.wait_for(lock, every, [&] { return stop_; });
      }
    });
  }

  void Stop() {
    if (!printer_.joinable()) return;
    {
      std::lock_guard lock(stop_mu_);
      stop_ = true;
    }
    stop_cv_.notify_all();
    printer_.join();
    Draw();
  }

 private:
  void Draw() {
    if (options_.progress == nullptr) return;
    std::vector<std::string> lines;
    {
      std::lock_guard lock(board_mu_);
      lines = board_.Render(clock_.NowS());
    }
    std::string out;
    if (options_.progress_tty && drawn_ > 0) out += "\x1b[" + std::to_string(drawn_) + "A";
    for (const std::string& l : lines) out += (options_.progress_tty ? "\x1b[2K" : "") + l + "\n";
    *options_.progress << out << std::flush;
    drawn_ = lines.size();
  }

  const ExperimentOptions& options_;
  ProgressBoard& board_;
  std::mutex& board_mu_;
  runner::Clock& clock_;
  std::mutex stop_mu_;
  std::condition_variable stop_cv_;
  bool stop_ = false;
  std::thread printer_;
  std::size_t drawn_ = 0;  // lines of the last drawing (the printer's thread, then Stop's)
};

// One executor per host (and its background remover when asked). The removers are declared
// before the executors, so they outlive them; each drains its queue when destroyed.
struct PoolWorkers {
  std::vector<std::unique_ptr<BackgroundRemover>> removers;
  std::vector<std::unique_ptr<TrialExecutor>> executors;
  std::vector<HostWorker*> workers;
};

PoolWorkers MakePoolWorkers(Session& session, const std::vector<PoolHost>& pool, const ExperimentOptions& options) {
  PoolWorkers w;
  for (const PoolHost& h : pool) {
    BackgroundRemover* remover = nullptr;
    if (options.remove_in_background) {
      w.removers.push_back(std::make_unique<BackgroundRemover>(*h.api, h.name));
      remover = w.removers.back().get();
    }
    w.executors.push_back(std::make_unique<TrialExecutor>(session, h, remover));
    w.workers.push_back(w.executors.back().get());
  }
  return w;
}

// Every removal still queued is carried out before the leftover sweep (and on Ctrl-C too).
void DrainRemovers(const PoolWorkers& w, std::vector<std::string>* problems) {
  for (const auto& remover : w.removers) {
    remover->Drain();
    for (std::string& p : remover->TakeProblems()) problems->push_back("clean-up: " + std::move(p));
  }
}

// Nothing of this run may stay on any host it can still reach.
void SweepLeftovers(const std::vector<PoolHost>& pool, const std::string& run_id, std::vector<std::string>* problems) {
  docker::LabelSelector sel;
  sel.equals[std::string(docker::kLabelRun)] = run_id;
  for (const PoolHost& h : pool) {
    if (Status up = h.check(); !up) {
      problems->push_back("could not check " + h.name + " for leftovers (" + up.error().message() +
                          "): when it is back, run `swarmbox gc --run " + run_id + "` against it");
      continue;
    }
    auto removed = docker::RemoveLabelled(*h.api, sel, false);
    if (!removed) {
      problems->push_back("listing leftovers on " + h.name + ": " + removed.error().ToString());
    } else if (!removed->containers.empty() || !removed->networks.empty()) {
      problems->push_back("removed leftovers on " + h.name + ": " + std::to_string(removed->containers.size()) +
                          " containers, " + std::to_string(removed->networks.size()) + " networks");
    }
  }
}

// The committed trials into *summary (count, outcomes); returns their provenance.
std::vector<report::Provenance> CountCommitted(const ExperimentPlan& plan, const TrialStore& store,
                                               ExperimentSummary* summary) {
  std::vector<report::Provenance> trials;
  for (const PlannedTrial& t : plan.trials) {
    if (!store.Done(t.id)) continue;
    ++summary->committed;
    if (auto rec = report::ReadTrialFolder(store.TrialDir(t.id))) {
      summary->outcomes[rec->outcome] += 1;
      trials.push_back(rec->provenance);
    }
  }
  return trials;
}

}  // namespace

namespace {

// The folder checked (a fresh one, or the one to resume), what earlier runs of it left on the
// hosts removed, its staging cleared and experiment.json written; returns every run id of the
// folder, this one last.
Result<std::vector<std::string>> OpenOutFolder(const ExperimentPlan& plan, const std::vector<PoolHost>& pool,
                                               const ExperimentOptions& options, TrialStore& store,
                                               const fs::path& meta_path, ExperimentSummary* summary) {
  auto previous = CheckOutFolder(plan, options.out_dir, options.resume);
  if (!previous) return previous.error();
  std::vector<std::string> run_ids = std::move(*previous);
  RemoveEarlierRuns(run_ids, pool, &summary->problems);
  SWARMBOX_TRY(store.ClearStaging());
  run_ids.push_back(options.run_id);
  SWARMBOX_TRY(WriteFileAtomic(meta_path.string(), ExperimentJson(plan, run_ids, pool)));
  return run_ids;
}

// After the schedule: the leftover sweep, the reports, the counts and experiment.json again, with
// what the trials' result.json say about their fault mechanism and pace.
void CloseOutFolder(const ExperimentPlan& plan, const std::vector<PoolHost>& pool, const ExperimentOptions& options,
                    const TrialStore& store, const fs::path& meta_path, const std::vector<std::string>& run_ids,
                    std::vector<std::string>& problems, ExperimentSummary* summary) {
  SweepLeftovers(pool, options.run_id, &problems);
  summary->problems.insert(summary->problems.end(), problems.begin(), problems.end());
  if (auto n = WriteReports(options.out_dir, &summary->problems); !n) {
    summary->problems.push_back("writing results.csv/report.html: " + n.error().ToString());
  }
  std::vector<report::Provenance> trials = CountCommitted(plan, store, summary);
  if (Status s = WriteFileAtomic(meta_path.string(), ExperimentJson(plan, run_ids, pool, trials)); !s) {
    summary->problems.push_back("writing experiment.json: " + s.error().ToString());
  }
}

}  // namespace

Result<ExperimentSummary> RunExperiment(const ExperimentPlan& plan, const std::vector<PoolHost>& pool,
                                        const ExperimentOptions& options) {
  auto dir_lock = DirLock::Acquire(options.out_dir);
  if (!dir_lock) return dir_lock.error();
  TrialStore store(options.out_dir);
  const fs::path meta_path = fs::path(options.out_dir) / "experiment.json";
  ExperimentSummary summary;
  auto run_ids = OpenOutFolder(plan, pool, options, store, meta_path, &summary);
  if (!run_ids) return run_ids.error();
  const std::vector<PlannedTrial> pending = store.Pending(plan.trials);
  summary.total = plan.trials.size();
  summary.done_before = plan.trials.size() - pending.size();

  Session session;
  session.plan = &plan;
  session.options = &options;
  session.store = &store;
  std::vector<std::pair<std::string, int>> host_rows;
  for (const PoolHost& h : pool) host_rows.emplace_back(h.name, h.slots);
  ProgressBoard board(host_rows, plan.trials.size(), summary.done_before);
  std::mutex board_mu;
  std::vector<std::string> problems;
  Observer observer(session, board, board_mu, problems);
  ProgressPrinter printer(options, board, board_mu, session.clock);
  printer.Start();

  PoolWorkers workers = MakePoolWorkers(session, pool, options);
  ScheduleOptions so;
  so.max_attempts = options.max_attempts;
  so.interrupted = options.interrupted;
  summary.reports = RunSchedule(pending, workers.workers, so, observer);
  (void)store.ClearStaging();  // every attempt has ended: committed, discarded or cancelled
  DrainRemovers(workers, &problems);
  printer.Stop();
  CloseOutFolder(plan, pool, options, store, meta_path, *run_ids, problems, &summary);
  return summary;
}

}  // namespace swarmbox::experiment
