// swarmbox compose TRIAL.yaml [-o FILE] [--set key=value ...]
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "load_trial.hpp"
#include "program_images.hpp"
#include "swarmbox/runner/compose_export.hpp"
#include "swarmbox/runner/derived_world.hpp"
#include "swarmbox/runner/naming.hpp"
#include "swarmbox/runner/plan.hpp"
#include "swarmbox/runner/radio_schedule.hpp"
#include "swarmbox/runner/user_images.hpp"

namespace swarmbox::cli {

namespace fs = std::filesystem;

// The run id of exported files: fixed, so an export is reproducible; `swarmbox gc --run compose`
// removes what `docker-compose up` made.
inline constexpr char kComposeRunId[] = "compose";

namespace {

constexpr int kContinue = -1;  // a step's "no exit yet"

// The physics and agent images (given, else the programs' content tags), then the trial's own
// software: packed programs by their content tags, Dockerfiles built by compose.
int ResolveImages(const ComposeArgs& args, const dsl::TrialSpec& spec, runner::Images* images) {
  images->physics = args.physics_image;
  images->agent = args.agent_image;
  if (images->physics.empty() || images->agent.empty()) {
    auto tags = TrialImageTags(args.programs);
    if (!tags) {
      std::cerr << "swarmbox compose: " << tags.error().ToString() << "\n";
      return kExitInfrastructure;
    }
    if (images->physics.empty()) images->physics = tags->physics;
    if (images->agent.empty()) images->agent = tags->agent;
  }
  std::string agent_bin;
  for (const dsl::DroneSpec& d : spec.drones) {
    if (d.brain.kind != dsl::BrainKind::kLibrary) continue;
    auto found = FindProgram("swarmbox-agent", args.programs.agent_bin);
    if (!found) {
      std::cerr << "swarmbox compose: " << found.error().ToString() << "\n";
      return kExitInfrastructure;
    }
    agent_bin = *found;
    break;
  }
  auto tags = runner::UserImageTags(spec, agent_bin, *images);
  if (!tags) {
    std::cerr << "swarmbox compose: " << tags.error().ToString() << "\n";
    return kExitInfrastructure;
  }
  *images = std::move(*tags);
  return kContinue;
}

// The files the trial names that `swarmbox run` would read: the payloads' airframes, the radio profile.
int CheckTrialFiles(const dsl::TrialSpec& spec, const std::string& trials_dir) {
  if (auto payloads = runner::LoadPayloadMasses(spec, trials_dir); !payloads) {
    std::cerr << payloads.error().ToString() << "\n";
    return kExitUsage;
  }
  if (Status s = runner::CheckRadioProfile(spec, trials_dir); !s) {
    std::cerr << "swarmbox compose: " << s.error().ToString() << "\n";
    return kExitUsage;
  }
  return kContinue;
}

// A file written next to the compose file (empty text: none).
struct SideFile {
  std::string text;
  fs::path file;
};

fs::path NextToOutput(const std::string& output, std::string_view suffix) {
  return fs::path(output).parent_path() / (fs::path(output).stem().string() + "." + std::string(suffix));
}

// radio.model channel: the radio plan (network.mesh, the faults at simulated times) is written
// next to the compose file and bind-mounted by a path relative to it; printed to stdout there is
// no place for it, and the channel runs unimpaired (compose carries out no faults either).
int PlanRadioFile(const ComposeArgs& args, const dsl::TrialSpec& spec, runner::PlanOptions* plan, SideFile* out) {
  if (spec.radio.model != dsl::RadioModel::kChannel) return kContinue;
  auto schedule = runner::PlanRadioSchedule(spec);
  if (!schedule) {
    std::cerr << "swarmbox compose: " << schedule.error().ToString() << "\n";
    return kExitUsage;
  }
  if (args.output.empty()) {
    std::cerr << "swarmbox compose: note: the radio plan (network.mesh, faults at simulated times) is exported "
                 "only with -o FILE, next to it\n";
  } else {
    out->text = runner::RadioScheduleJson(*schedule) + "\n";
    out->file = NextToOutput(args.output, runner::kRadioPlanFile);
    plan->radio_plan_path = "./" + out->file.filename().string();
  }
  return kContinue;
}

// world_size_m: the derived world (derived_world.hpp) next to the compose file, like the radio
// plan; printed to stdout the services would read the trial's world with its own geofence.
int PlanWorldFile(const ComposeArgs& args, const dsl::TrialSpec& spec, const std::string& trials_dir,
                  runner::PlanOptions* plan, SideFile* out) {
  if (!spec.HasDerivedWorld()) return kContinue;
  auto derived = runner::DerivedWorldText(spec, trials_dir);
  if (!derived) {
    std::cerr << "swarmbox compose: " << derived.error().ToString() << "\n";
    return kExitUsage;
  }
  if (args.output.empty()) {
    std::cerr << "swarmbox compose: error: world_size_m or a generated world needs -o FILE (the derived world is written next to it)\n";
    return kExitUsage;
  }
  out->text = std::move(*derived);
  out->file = NextToOutput(args.output, runner::kDerivedWorldFile);
  plan->world_path = "./" + out->file.filename().string();
  return kContinue;
}

// The Dockerfiles compose builds (brains and components), by a context relative to the output.
void AddBuilds(const ComposeArgs& args, const dsl::TrialSpec& spec, runner::ComposeOptions* compose) {
  auto build_of = [&](const std::string& service, const std::string& dockerfile) {
    const fs::path file = fs::absolute(dockerfile).lexically_normal();
    std::string context = file.parent_path().string();
    if (!args.output.empty()) {
      context = file.parent_path().lexically_relative(fs::absolute(args.output).parent_path()).string();
    }
    compose->builds[service] = {context, file.filename().string()};
  };
  for (const dsl::DroneSpec& d : spec.drones) {
    if (d.brain.kind == dsl::BrainKind::kDockerfile) build_of(runner::BrainId(d.name), d.brain.host_path);
  }
  for (const dsl::UserComponentSpec& c : spec.components) {
    if (c.source == dsl::ComponentSource::kDockerfile) build_of(c.name, c.host_path);
  }
}

runner::ComposeOptions ComposeOptionsFor(const ComposeArgs& args, const dsl::TrialSpec& spec,
                                         const std::string& trials_dir) {
  runner::ComposeOptions compose;
  AddBuilds(args, spec, &compose);
  std::string command = "swarmbox compose " + args.trial;
  for (const auto& s : args.sets) command += " --set " + s;
  if (!args.output.empty()) {
    command += " -o " + args.output;
    // Input files relative to the compose file, so the folder can move with the checkout.
    const fs::path out_dir = fs::absolute(args.output).parent_path();
    compose.host_prefix = trials_dir;
    compose.relative_prefix = fs::path(trials_dir).lexically_relative(out_dir).string();
  }
  compose.header_comment =
      "Exported by `" + command + "` (do not edit by hand; export again).\n"
      "Trial '" + spec.name + "': the same images, argv, environment, labels, networks and\n"
      "addresses as `swarmbox run`; run priority is depends_on (readiness waits are not\n"
      "modelled: compose starts a service once the one it depends on has started).\n"
      "Needs the images on this engine: run `swarmbox images` first (a trial's brain and\n"
      "component images: `swarmbox run` it once; a Dockerfile's image compose builds).\n"
      "  docker-compose -f <this file> up        # Ctrl-C, then copy what you need:\n"
      "  docker cp " + runner::ResourceName(spec.name, kComposeRunId, runner::kPhysicsId) +
      ":" + std::string(runner::kTruthCsvPath) + " .\n"
      "  docker-compose -f <this file> down -v   # or: swarmbox gc --run compose";
  return compose;
}

int WriteOutputFile(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) {
    std::cerr << "swarmbox compose: cannot write " << path.string() << "\n";
    return kExitInfrastructure;
  }
  std::cerr << "wrote " << path.string() << "\n";
  return kContinue;
}

// The radio plan and the derived world first, then the compose file.
int WriteOutputs(const std::string& output, const SideFile& radio_plan, const SideFile& world,
                 const std::string& text) {
  for (const SideFile* side : {&radio_plan, &world}) {
    if (side->text.empty()) continue;
    if (int code = WriteOutputFile(side->file, side->text); code != kContinue) return code;
  }
  if (int code = WriteOutputFile(output, text); code != kContinue) return code;
  return kExitOk;
}

}  // namespace

int ComposeCommand(const ComposeArgs& args) {
  auto spec = LoadTrialOrPrintError(args.trial, args.sets);
  if (!spec) return kExitUsage;
  runner::Images images;
  if (int code = ResolveImages(args, *spec, &images); code != kContinue) return code;
  auto subnets = runner::PickSubnets(kComposeRunId, 0, {});
  if (!subnets) {
    std::cerr << "swarmbox compose: " << subnets.error().ToString() << "\n";
    return kExitInfrastructure;
  }
  const std::string trials_dir = fs::absolute(spec->trials_dir).lexically_normal().string();
  if (int code = CheckTrialFiles(*spec, trials_dir); code != kContinue) return code;
  runner::PlanOptions plan;
  plan.run_id = kComposeRunId;
  plan.images = images;
  plan.subnets = *subnets;
  plan.trials_dir = trials_dir;
  SideFile radio_plan;
  SideFile world;
  if (int code = PlanRadioFile(args, *spec, &plan, &radio_plan); code != kContinue) return code;
  if (int code = PlanWorldFile(args, *spec, trials_dir, &plan, &world); code != kContinue) return code;
  auto trial = runner::PlanTrial(*spec, plan);
  if (!trial) {
    std::cerr << "swarmbox compose: " << trial.error().ToString() << "\n";
    return kExitUsage;
  }
  const std::string text = runner::ComposeYaml(**trial, ComposeOptionsFor(args, *spec, trials_dir));
  if (args.output.empty()) {
    std::cout << text;
    return kExitOk;
  }
  return WriteOutputs(args.output, radio_plan, world, text);
}

}  // namespace swarmbox::cli
