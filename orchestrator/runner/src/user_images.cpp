#include "swarmbox/runner/user_images.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "swarmbox/docker/tar_archive.hpp"
#include "swarmbox/images/content_hash.hpp"
#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/image_context.hpp"
#include "swarmbox/images/standard_images.hpp"

namespace swarmbox::runner {

namespace fs = std::filesystem;

namespace {

std::string Basename(const std::string& path) { return fs::path(path).filename().string(); }

std::string HostPath(const std::string& host_path, const std::string& as_written) {
  return host_path.empty() ? as_written : host_path;
}

// Docker repository names are lower case [a-z0-9._-]; component names already are, '_' included.
std::string UserRepository(std::string_view name) { return "swarmbox/user-" + std::string(name); }

struct Needs {
  std::vector<const dsl::DroneSpec*> library_brains;
  std::vector<const dsl::DroneSpec*> external_brains;
};

Needs WhatTheTrialNeeds(const dsl::TrialSpec& spec) {
  Needs n;
  for (const dsl::DroneSpec& d : spec.drones) {
    if (d.brain.kind == dsl::BrainKind::kLibrary) n.library_brains.push_back(&d);
    if (d.brain.external()) n.external_brains.push_back(&d);
  }
  return n;
}

Status NeedAgentBinary(const std::string& agent_binary, const dsl::DroneSpec& d) {
  if (!agent_binary.empty()) return Ok{};
  return Error(ErrorCode::kInvalidArgument,
               "drone " + d.name + " flies a library brain: its agent image is packed from the host swarmbox-agent, "
               "and none was given (--agent-bin, or RunOptions::agent_binary)",
               d.brain.mark.ToString());
}

Status CheckLocalImage(docker::DockerApi& api, const std::string& reference, const std::string& who) {
  auto info = api.InspectImage(reference);
  if (info) return Ok{};
  if (info.error().code() == ErrorCode::kNotFound) {
    return Error(ErrorCode::kNotFound,
                 who + ": image '" + reference +
                     "' is not on the engine (SwarmBox never pulls: build it or `docker load` it first)");
  }
  return info.error().Context(who + ": image " + reference);
}

}  // namespace

images::ImageSpec AgentWithBrainImage(const std::string& agent_binary, const std::string& library) {
  images::ImageSpec spec = images::AgentImage(agent_binary);
  spec.repository = kAgentBrainRepository;
  spec.component = "agent";
  // dlopen()ed by the agent: the packer adds the library's own closure (a plugin, not a program).
  spec.plugins.push_back({library, std::string(kBrainsDir) + "/" + Basename(library), 0644});
  return spec;
}

images::ImageSpec ProgramImage(const std::string& repository, const std::string& component,
                               const std::string& binary, const std::vector<std::string>& collect) {
  images::ImageSpec spec;
  spec.repository = repository;
  spec.component = component;
  const std::string in_image = std::string(kProgramDirInImage) + "/" + Basename(binary);
  spec.executables.push_back({binary, in_image, 0755});
  spec.entrypoint = {in_image};
  images::AddSwarmboxBaseFiles(&spec);
  // The program runs as uid 1000 on a FROM scratch root: the folders it is to write the collected
  // files into must be writable for it.
  for (const std::string& path : collect) {
    const fs::path parent = fs::path(path).parent_path();
    if (parent.empty() || parent == "/" || spec.directories.count(parent.string()) > 0) continue;
    spec.directories[parent.string()] = 01777;
  }
  return spec;
}

Result<DockerfileContext> PackDockerfileContext(const std::string& dockerfile, std::string_view name) {
  const fs::path file = fs::absolute(dockerfile).lexically_normal();
  const fs::path folder = file.parent_path();
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    return Error(ErrorCode::kNotFound, "Dockerfile not found", file.string());
  }
  std::vector<docker::TarEntry> entries;
  for (fs::recursive_directory_iterator it(folder, fs::directory_options::none, ec), end; !ec && it != end;
       it.increment(ec)) {
    const fs::path relative = it->path().lexically_relative(folder);
    docker::TarEntry e;
    e.path = relative.generic_string();
    const auto status = it->symlink_status(ec);
    if (ec) break;
    if (fs::is_symlink(status)) {
      e.type = docker::TarEntry::Type::kSymlink;
      e.content = fs::read_symlink(it->path(), ec).string();
      e.mode = 0777;
    } else if (fs::is_directory(status)) {
      e.type = docker::TarEntry::Type::kDirectory;
      e.mode = static_cast<std::uint32_t>(status.permissions()) & 07777;
    } else if (fs::is_regular_file(status)) {
      std::ifstream in(it->path(), std::ios::binary);
      std::ostringstream bytes;
      bytes << in.rdbuf();
      if (!in) return Error(ErrorCode::kIo, "cannot read a file of the Dockerfile's context", it->path().string());
      e.content = bytes.str();
      e.mode = static_cast<std::uint32_t>(status.permissions()) & 07777;
    } else {
      continue;  // sockets, fifos: not part of a build context
    }
    if (ec) break;
    entries.push_back(std::move(e));
  }
  if (ec) return Error(ErrorCode::kIo, "cannot read the Dockerfile's folder: " + ec.message(), folder.string());
  std::sort(entries.begin(), entries.end(),
            [](const docker::TarEntry& a, const docker::TarEntry& b) { return a.path < b.path; });
  docker::TarWriter writer;
  for (const docker::TarEntry& e : entries) SWARMBOX_TRY(writer.Add(e));
  auto tar = writer.Finish();
  if (!tar) return tar.error();
  DockerfileContext out;
  out.dockerfile = file.filename().string();
  out.tag = UserRepository(name) + ":" + images::Sha256Hex(*tar).substr(0, images::kTagHashDigits);
  out.tar = std::move(*tar);
  return out;
}

Result<std::string> EnsureDockerfileImage(docker::DockerApi& api, const std::string& dockerfile,
                                          std::string_view name,
                                          const std::function<void(std::string_view)>& progress) {
  auto ctx = PackDockerfileContext(dockerfile, name);
  if (!ctx) return ctx.error();
  if (api.InspectImage(ctx->tag)) return ctx->tag;
  docker::BuildRequest request;
  request.context_tar = std::move(ctx->tar);
  request.dockerfile = ctx->dockerfile;
  request.tags = {ctx->tag};
  request.labels = {{"swarmbox.image", UserRepository(name)}, {"swarmbox.component", std::string(name)}};
  request.pull = false;
  auto built = api.BuildImage(request, progress, nullptr);
  if (!built) {
    return built.error().Context("building " + dockerfile +
                                 " (SwarmBox uses no registry: its FROM images must already be on the engine)");
  }
  return ctx->tag;
}

Result<Images> EnsureUserImages(docker::DockerApi& api, const dsl::TrialSpec& spec,
                                const std::string& agent_binary, Images base,
                                const std::function<void(std::string_view)>& progress,
                                const images::TagCache* cache) {
  const Needs needs = WhatTheTrialNeeds(spec);
  auto ensure = [&](const images::ImageSpec& image, const std::string& who) -> Result<std::string> {
    auto r = images::EnsureImage(api, image, progress, nullptr, cache);
    if (!r) return r.error().Context(who);
    return r->tag;
  };
  for (const dsl::DroneSpec* d : needs.library_brains) {
    SWARMBOX_TRY(NeedAgentBinary(agent_binary, *d));
    auto tag = ensure(AgentWithBrainImage(agent_binary, HostPath(d->brain.host_path, d->brain.path)),
                      "the agent image of " + d->name + " with its brain library");
    if (!tag) return tag.error();
    base.drone_agents[d->name] = *tag;
  }
  for (const dsl::DroneSpec* d : needs.external_brains) {
    const std::string who = "the brain of " + d->name;
    const std::string path = HostPath(d->brain.host_path, d->brain.path);
    if (d->brain.kind == dsl::BrainKind::kProgram) {
      auto tag = ensure(ProgramImage(kBrainRepository, "brain", path), who);
      if (!tag) return tag.error();
      base.brains[d->name] = *tag;
    } else if (d->brain.kind == dsl::BrainKind::kDockerfile) {
      auto tag = EnsureDockerfileImage(api, path, BrainId(d->name), progress);
      if (!tag) return tag.error().Context(who);
      base.brains[d->name] = *tag;
    } else {
      SWARMBOX_TRY(CheckLocalImage(api, d->brain.path, who));
      base.brains[d->name] = d->brain.path;
    }
  }
  for (const dsl::UserComponentSpec& c : spec.components) {
    const std::string who = "component " + c.name;
    const std::string path = HostPath(c.host_path, c.ref);
    if (c.source == dsl::ComponentSource::kProgram) {
      auto tag = ensure(ProgramImage(kComponentRepository, c.name, path, c.collect), who);
      if (!tag) return tag.error();
      base.components[c.name] = *tag;
    } else if (c.source == dsl::ComponentSource::kDockerfile) {
      auto tag = EnsureDockerfileImage(api, path, c.name, progress);
      if (!tag) return tag.error().Context(who);
      base.components[c.name] = *tag;
    } else {
      SWARMBOX_TRY(CheckLocalImage(api, c.ref, who));
      base.components[c.name] = c.ref;
    }
  }
  return base;
}

Result<Images> UserImageTags(const dsl::TrialSpec& spec, const std::string& agent_binary, Images base) {
  const Needs needs = WhatTheTrialNeeds(spec);
  auto tag_of = [](const images::ImageSpec& image, const std::string& who) -> Result<std::string> {
    auto ctx = images::PackContext(image);
    if (!ctx) return ctx.error().Context(who);
    return ctx->tag;
  };
  for (const dsl::DroneSpec* d : needs.library_brains) {
    SWARMBOX_TRY(NeedAgentBinary(agent_binary, *d));
    auto tag = tag_of(AgentWithBrainImage(agent_binary, HostPath(d->brain.host_path, d->brain.path)),
                      "the agent image of " + d->name);
    if (!tag) return tag.error();
    base.drone_agents[d->name] = *tag;
  }
  for (const dsl::DroneSpec* d : needs.external_brains) {
    const std::string path = HostPath(d->brain.host_path, d->brain.path);
    Result<std::string> tag = d->brain.path;
    if (d->brain.kind == dsl::BrainKind::kProgram) tag = tag_of(ProgramImage(kBrainRepository, "brain", path), d->name);
    if (d->brain.kind == dsl::BrainKind::kDockerfile) {
      auto ctx = PackDockerfileContext(path, BrainId(d->name));
      tag = ctx ? Result<std::string>(ctx->tag) : Result<std::string>(ctx.error());
    }
    if (!tag) return tag.error();
    base.brains[d->name] = *tag;
  }
  for (const dsl::UserComponentSpec& c : spec.components) {
    const std::string path = HostPath(c.host_path, c.ref);
    Result<std::string> tag = c.ref;
    if (c.source == dsl::ComponentSource::kProgram) {
      tag = tag_of(ProgramImage(kComponentRepository, c.name, path, c.collect), c.name);
    }
    if (c.source == dsl::ComponentSource::kDockerfile) {
      auto ctx = PackDockerfileContext(path, c.name);
      tag = ctx ? Result<std::string>(ctx->tag) : Result<std::string>(ctx.error());
    }
    if (!tag) return tag.error();
    base.components[c.name] = *tag;
  }
  return base;
}

}  // namespace swarmbox::runner
