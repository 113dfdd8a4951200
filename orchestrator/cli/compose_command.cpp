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

int ComposeCommand(const ComposeArgs& args) {
  auto spec = LoadTrialOrPrintError(args.trial, args.sets);
  if (!spec) return kExitUsage;
  runner::Images images;
  images.physics = args.physics_image;
  images.agent = args.agent_image;
  if (images.physics.empty() || images.agent.empty()) {
    auto tags = TrialImageTags(args.programs);
    if (!tags) {
      std::cerr << "swarmbox compose: " << tags.error().ToString() << "\n";
      return kExitInfrastructure;
    }
    if (images.physics.empty()) images.physics = tags->physics;
    if (images.agent.empty()) images.agent = tags->agent;
  }
  // The trial's own software: packed programs by their content tags, Dockerfiles built by compose.
  {
    std::string agent_bin;
    for (const dsl::DroneSpec& d : spec->drones) {
      if (d.brain.kind != dsl::BrainKind::kLibrary) continue;
      auto found = FindProgram("swarmbox-agent", args.programs.agent_bin);
      if (!found) {
        std::cerr << "swarmbox compose: " << found.error().ToString() << "\n";
        return kExitInfrastructure;
      }
      agent_bin = *found;
      break;
    }
    auto tags = runner::UserImageTags(*spec, agent_bin, images);
    if (!tags) {
      std::cerr << "swarmbox compose: " << tags.error().ToString() << "\n";
      return kExitInfrastructure;
    }
    images = std::move(*tags);
  }
  auto subnets = runner::PickSubnets(kComposeRunId, 0, {});
  if (!subnets) {
    std::cerr << "swarmbox compose: " << subnets.error().ToString() << "\n";
    return kExitInfrastructure;
  }
  const std::string trials_dir = fs::absolute(spec->trials_dir).lexically_normal().string();
  if (auto payloads = runner::LoadPayloadMasses(*spec, trials_dir); !payloads) {
    std::cerr << payloads.error().ToString() << "\n";
    return kExitUsage;
  }
  if (Status s = runner::CheckRadioProfile(*spec, trials_dir); !s) {
    std::cerr << "swarmbox compose: " << s.error().ToString() << "\n";
    return kExitUsage;
  }
  runner::PlanOptions plan;
  plan.run_id = kComposeRunId;
  plan.images = images;
  plan.subnets = *subnets;
  plan.trials_dir = trials_dir;
  // radio.model channel: the radio plan (network.mesh, the faults at simulated times) is written
  // next to the compose file and bind-mounted by a path relative to it; printed to stdout there is
  // no place for it, and the channel runs unimpaired (compose carries out no faults either).
  std::string radio_plan_text;
  fs::path radio_plan_file;
  if (spec->radio.model == dsl::RadioModel::kChannel) {
    auto schedule = runner::PlanRadioSchedule(*spec);
    if (!schedule) {
      std::cerr << "swarmbox compose: " << schedule.error().ToString() << "\n";
      return kExitUsage;
    }
    if (args.output.empty()) {
      std::cerr << "swarmbox compose: note: the radio plan (network.mesh, faults at simulated times) is exported "
                   "only with -o FILE, next to it\n";
    } else {
      radio_plan_text = runner::RadioScheduleJson(*schedule) + "\n";
      radio_plan_file = fs::path(args.output).parent_path() /
                        (fs::path(args.output).stem().string() + "." + std::string(runner::kRadioPlanFile));
      plan.radio_plan_path = "./" + radio_plan_file.filename().string();
    }
  }
  // world_size_m: the derived world (derived_world.hpp) next to the compose file, like the radio
  // plan; printed to stdout the services would read the trial's world with its own geofence.
  std::string world_text;
  fs::path world_file;
  if (spec->HasDerivedWorld()) {
    auto derived = runner::DerivedWorldText(*spec, trials_dir);
    if (!derived) {
      std::cerr << "swarmbox compose: " << derived.error().ToString() << "\n";
      return kExitUsage;
    }
    if (args.output.empty()) {
      std::cerr << "swarmbox compose: error: world_size_m or a generated world needs -o FILE (the derived world is written next to it)\n";
      return kExitUsage;
    }
    world_text = std::move(*derived);
    world_file = fs::path(args.output).parent_path() /
                 (fs::path(args.output).stem().string() + "." + std::string(runner::kDerivedWorldFile));
    plan.world_path = "./" + world_file.filename().string();
  }
  auto trial = runner::PlanTrial(*spec, plan);
  if (!trial) {
    std::cerr << "swarmbox compose: " << trial.error().ToString() << "\n";
    return kExitUsage;
  }
  runner::ComposeOptions compose;
  auto build_of = [&](const std::string& service, const std::string& dockerfile) {
    const fs::path file = fs::absolute(dockerfile).lexically_normal();
    std::string context = file.parent_path().string();
    if (!args.output.empty()) {
      context = file.parent_path().lexically_relative(fs::absolute(args.output).parent_path()).string();
    }
    compose.builds[service] = {context, file.filename().string()};
  };
  for (const dsl::DroneSpec& d : spec->drones) {
    if (d.brain.kind == dsl::BrainKind::kDockerfile) build_of(runner::BrainId(d.name), d.brain.host_path);
  }
  for (const dsl::UserComponentSpec& c : spec->components) {
    if (c.source == dsl::ComponentSource::kDockerfile) build_of(c.name, c.host_path);
  }
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
      "Trial '" + spec->name + "': the same images, argv, environment, labels, networks and\n"
      "addresses as `swarmbox run`; run priority is depends_on (readiness waits are not\n"
      "modelled: compose starts a service once the one it depends on has started).\n"
      "Needs the images on this engine: run `swarmbox images` first (a trial's brain and\n"
      "component images: `swarmbox run` it once; a Dockerfile's image compose builds).\n"
      "  docker-compose -f <this file> up        # Ctrl-C, then copy what you need:\n"
      "  docker cp " + runner::ResourceName(spec->name, kComposeRunId, runner::kPhysicsId) +
      ":" + std::string(runner::kTruthCsvPath) + " .\n"
      "  docker-compose -f <this file> down -v   # or: swarmbox gc --run compose";
  const std::string text = runner::ComposeYaml(**trial, compose);
  if (args.output.empty()) {
    std::cout << text;
    return kExitOk;
  }
  if (!radio_plan_text.empty()) {
    std::ofstream plan_out(radio_plan_file, std::ios::binary | std::ios::trunc);
    plan_out << radio_plan_text;
    plan_out.close();
    if (!plan_out) {
      std::cerr << "swarmbox compose: cannot write " << radio_plan_file.string() << "\n";
      return kExitInfrastructure;
    }
    std::cerr << "wrote " << radio_plan_file.string() << "\n";
  }
  if (!world_text.empty()) {
    std::ofstream world_out(world_file, std::ios::binary | std::ios::trunc);
    world_out << world_text;
    world_out.close();
    if (!world_out) {
      std::cerr << "swarmbox compose: cannot write " << world_file.string() << "\n";
      return kExitInfrastructure;
    }
    std::cerr << "wrote " << world_file.string() << "\n";
  }
  std::ofstream out(args.output, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) {
    std::cerr << "swarmbox compose: cannot write " << args.output << "\n";
    return kExitInfrastructure;
  }
  std::cerr << "wrote " << args.output << "\n";
  return kExitOk;
}

}  // namespace swarmbox::cli
