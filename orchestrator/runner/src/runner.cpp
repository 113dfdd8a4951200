#include "swarmbox/runner/runner.hpp"

#include <cstdio>
#include <filesystem>
#include <functional>
#include <ostream>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/images/tag_cache.hpp"
#include "swarmbox/runner/derived_world.hpp"
#include "swarmbox/runner/fault_image.hpp"
#include "swarmbox/runner/naming.hpp"
#include "swarmbox/runner/radio_schedule.hpp"
#include "swarmbox/runner/user_images.hpp"
#include "trial_run.hpp"

namespace swarmbox::runner {

namespace fs = std::filesystem;

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
  detail::TrialRun run(info, planner, api, clock, o);
  return run.Run();
}

namespace {

// How RunTrialSpec reports the images it makes.
std::function<void(std::string_view)> ImageProgress(const RunOptions& options) {
  return [&options](std::string_view line) {
    if (options.progress != nullptr) *options.progress << "  " << line << std::endl;
  };
}

// What RunTrial needs besides the tree, with the files it writes into the trial folder (the
// derived world, the radio plan).
Result<TrialInfo> TrialInfoFor(const dsl::TrialSpec& spec, const std::string& trials_dir) {
  TrialInfo info;
  info.name = spec.name;
  info.seed = spec.seed;
  info.rtf = spec.rtf;
  info.resolved_yaml = yaml::Emit(spec.document.is_null() ? dsl::ToDocument(spec) : spec.document);
  info.world_file = (fs::path(trials_dir) / spec.world).string();
  if (spec.HasDerivedWorld()) {  // the world every container reads, written into the trial folder
    auto derived = DerivedWorldText(spec, trials_dir);
    if (!derived) return derived.error();
    info.files[std::string(kDerivedWorldFile)] = std::move(*derived);
  }
  if (auto payloads = LoadPayloadMasses(spec, trials_dir); !payloads) {
    return payloads.error().Context("checking payloads");
  }
  for (const dsl::DroneSpec& d : spec.drones) info.drones.push_back(d.name);
  info.middleware = spec.middleware;
  info.radio_model = std::string(dsl::RadioModelName(spec.radio.model));
  if (spec.radio.model != dsl::RadioModel::kChannel) {
    info.mesh = spec.mesh;
    info.faults = spec.faults;
    return info;
  }
  // The simulated radio: network.mesh and the faults at simulated times go to the physics server
  // in the radio plan; the rest (on:, at_wall:) stay with the fault injector.
  info.radio_profile = spec.radio.profile;
  SWARMBOX_TRY(CheckRadioProfile(spec, trials_dir));
  auto plan = PlanRadioSchedule(spec);
  if (!plan) return plan.error().Context("the radio plan");
  info.files[std::string(kRadioPlanFile)] = RadioScheduleJson(*plan) + "\n";
  for (const faults::Fault& f : spec.faults) (InRadioSchedule(f) ? info.planned_faults : info.faults).push_back(f);
  return info;
}

// RunOptions::faults_image, else the fault sidecar image built here when the trial needs one.
Result<std::string> FaultsImageFor(const dsl::TrialSpec& spec, docker::DockerApi& api, const RunOptions& options) {
  if (!NeedsFaultSidecars(spec) || !options.faults_image.empty()) return options.faults_image;
  auto netemd = FindNetemd(options.netemd_bin);
  if (!netemd) return netemd.error().Context("the fault sidecar image");
  return EnsureFaultsImage(api, *netemd, ImageProgress(options));
}

// RunOptions::images with the images of the trial's own software that the caller did not bring.
Result<Images> ImagesFor(const dsl::TrialSpec& spec, docker::DockerApi& api, const RunOptions& options) {
  const Images& images = options.images;
  bool missing = false;
  for (const dsl::DroneSpec& d : spec.drones) {
    missing = missing || (d.brain.kind == dsl::BrainKind::kLibrary && images.drone_agents.count(d.name) == 0) ||
              (d.brain.external() && images.brains.count(d.name) == 0);
  }
  for (const dsl::UserComponentSpec& c : spec.components) missing = missing || images.components.count(c.name) == 0;
  if (!missing) return images;
  const images::TagCache cache(images::DefaultTagCacheDir());
  return EnsureUserImages(api, spec, options.agent_binary, images, ImageProgress(options), &cache);
}

// PlanTrial for each pair of subnets RunTrial tries. `spec` and `options` must outlive it.
Planner SpecPlanner(const dsl::TrialSpec& spec, const RunOptions& options, std::string trials_dir,
                    std::string faults_image, Images images) {
  return [&spec, &options, trials_dir = std::move(trials_dir), faults_image = std::move(faults_image),
          images = std::move(images)](const std::string& run_id, const TrialSubnets& subnets) {
    PlanOptions p;
    const fs::path trial_dir = fs::absolute(options.out_dir) / TrialDirName(spec.name, run_id);
    if (spec.radio.model == dsl::RadioModel::kChannel) {  // RunTrial wrote it (info.files) into the trial folder
      p.radio_plan_path = (trial_dir / kRadioPlanFile).lexically_normal().string();
    }
    if (spec.HasDerivedWorld()) {  // RunTrial wrote it (info.files) into the trial folder
      p.world_path = (trial_dir / kDerivedWorldFile).lexically_normal().string();
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
}

}  // namespace

Result<RunOutcome> RunTrialSpec(const dsl::TrialSpec& spec, docker::DockerApi& api, Clock& clock,
                                const RunOptions& options) {
  if (options.view && options.host != "local") {
    return Error(ErrorCode::kInvalidArgument, "--view publishes the live view on this machine; host '" + options.host +
                                                  "' is remote (run the trial on the local engine to watch it)");
  }
  std::string trials_dir =
      fs::absolute(spec.trials_dir.empty() ? fs::path(".") : fs::path(spec.trials_dir)).lexically_normal().string();
  auto info = TrialInfoFor(spec, trials_dir);
  if (!info) return info.error();
  auto faults_image = FaultsImageFor(spec, api, options);
  if (!faults_image) return faults_image.error();
  auto images = ImagesFor(spec, api, options);
  if (!images) return images.error();
  const Planner planner = SpecPlanner(spec, options, std::move(trials_dir), std::move(*faults_image), std::move(*images));
  return RunTrial(*info, planner, api, clock, options);
}

}  // namespace swarmbox::runner
