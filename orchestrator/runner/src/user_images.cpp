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

namespace {

// One entry of a Dockerfile's folder into `e`: a symlink, a directory or a regular file (false for
// what a build context leaves out: sockets, fifos). An unreadable file is the error; a symlink that
// cannot be read sets `ec`.
Result<bool> ReadContextEntry(const fs::path& path, const fs::file_status& status, docker::TarEntry* e,
                              std::error_code& ec) {
  if (fs::is_symlink(status)) {
    e->type = docker::TarEntry::Type::kSymlink;
    e->content = fs::read_symlink(path, ec).string();
    e->mode = 0777;
    return true;
  }
  if (fs::is_directory(status)) {
    e->type = docker::TarEntry::Type::kDirectory;
    e->mode = static_cast<std::uint32_t>(status.permissions()) & 07777;
    return true;
  }
  if (!fs::is_regular_file(status)) return false;
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (!in) return Error(ErrorCode::kIo, "cannot read a file of the Dockerfile's context", path.string());
  e->content = bytes.str();
  e->mode = static_cast<std::uint32_t>(status.permissions()) & 07777;
  return true;
}

// Everything below the Dockerfile's folder, sorted by path (the tar, and so its hash, does not
// depend on the order the file system lists it in).
Result<std::vector<docker::TarEntry>> ReadContextFolder(const fs::path& folder) {
  std::error_code ec;
  std::vector<docker::TarEntry> entries;
  for (fs::recursive_directory_iterator it(folder, fs::directory_options::none, ec), end; !ec && it != end;
       it.increment(ec)) {
    docker::TarEntry e;
    e.path = it->path().lexically_relative(folder).generic_string();
    const auto status = it->symlink_status(ec);
    if (ec) break;
    auto kept = ReadContextEntry(it->path(), status, &e, ec);
    if (!kept) return kept.error();
    if (!*kept) continue;
    if (ec) break;
    entries.push_back(std::move(e));
  }
  if (ec) return Error(ErrorCode::kIo, "cannot read the Dockerfile's folder: " + ec.message(), folder.string());
  std::sort(entries.begin(), entries.end(),
            [](const docker::TarEntry& a, const docker::TarEntry& b) { return a.path < b.path; });
  return entries;
}

}  // namespace

Result<DockerfileContext> PackDockerfileContext(const std::string& dockerfile, std::string_view name) {
  const fs::path file = fs::absolute(dockerfile).lexically_normal();
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    return Error(ErrorCode::kNotFound, "Dockerfile not found", file.string());
  }
  auto entries = ReadContextFolder(file.parent_path());
  if (!entries) return entries.error();
  docker::TarWriter writer;
  for (const docker::TarEntry& e : *entries) SWARMBOX_TRY(writer.Add(e));
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

namespace {

// An external brain's or a user component's image as the trial gives it: a program packed into
// an image, a Dockerfile built, or an image reference already on the engine.
struct UserImage {
  enum class Source { kProgram, kDockerfile, kImage };
  Source source = Source::kImage;
  std::string name;        // the drone (brain) or the component: its key in Images
  std::string who;         // in errors: "the brain of scout_1", "component recorder"
  std::string path;        // kProgram, kDockerfile: on the host
  std::string reference;   // kImage
  std::string build_name;  // kDockerfile: the image's name (BrainId for a brain)
  // kProgram: ProgramImage's repository, component and collected files.
  std::string repository;
  std::string component;
  std::vector<std::string> collect;
};

UserImage BrainImage(const dsl::DroneSpec& d) {
  UserImage u;
  u.source = d.brain.kind == dsl::BrainKind::kProgram      ? UserImage::Source::kProgram
             : d.brain.kind == dsl::BrainKind::kDockerfile ? UserImage::Source::kDockerfile
                                                           : UserImage::Source::kImage;
  u.name = d.name;
  u.who = "the brain of " + d.name;
  u.path = HostPath(d.brain.host_path, d.brain.path);
  u.reference = d.brain.path;
  u.build_name = BrainId(d.name);
  u.repository = std::string(kBrainRepository);
  u.component = "brain";
  return u;
}

UserImage ComponentImage(const dsl::UserComponentSpec& c) {
  UserImage u;
  u.source = c.source == dsl::ComponentSource::kProgram      ? UserImage::Source::kProgram
             : c.source == dsl::ComponentSource::kDockerfile ? UserImage::Source::kDockerfile
                                                             : UserImage::Source::kImage;
  u.name = c.name;
  u.who = "component " + c.name;
  u.path = HostPath(c.host_path, c.ref);
  u.reference = c.ref;
  u.build_name = c.name;
  u.repository = std::string(kComponentRepository);
  u.component = c.name;
  u.collect = c.collect;
  return u;
}

// The image on the engine (packed, built or checked), its tag.
Result<std::string> EnsureUserImage(docker::DockerApi& api, const UserImage& u,
                                    const std::function<void(std::string_view)>& progress,
                                    const images::TagCache* cache) {
  switch (u.source) {
    case UserImage::Source::kProgram: {
      auto r = images::EnsureImage(api, ProgramImage(u.repository, u.component, u.path, u.collect), progress,
                                   nullptr, cache);
      if (!r) return r.error().Context(u.who);
      return r->tag;
    }
    case UserImage::Source::kDockerfile: {
      auto tag = EnsureDockerfileImage(api, u.path, u.build_name, progress);
      if (!tag) return tag.error().Context(u.who);
      return tag;
    }
    case UserImage::Source::kImage: break;
  }
  SWARMBOX_TRY(CheckLocalImage(api, u.reference, u.who));
  return u.reference;
}

// The tag the image would have, without an engine (a program's packed context, a Dockerfile's
// folder, the reference itself).
Result<std::string> UserImageTag(const UserImage& u) {
  switch (u.source) {
    case UserImage::Source::kProgram: {
      auto ctx = images::PackContext(ProgramImage(u.repository, u.component, u.path, u.collect));
      if (!ctx) return ctx.error().Context(u.name);
      return ctx->tag;
    }
    case UserImage::Source::kDockerfile: {
      auto ctx = PackDockerfileContext(u.path, u.build_name);
      if (!ctx) return ctx.error();
      return ctx->tag;
    }
    case UserImage::Source::kImage: break;
  }
  return u.reference;
}

}  // namespace

Result<Images> EnsureUserImages(docker::DockerApi& api, const dsl::TrialSpec& spec,
                                const std::string& agent_binary, Images base,
                                const std::function<void(std::string_view)>& progress,
                                const images::TagCache* cache) {
  const Needs needs = WhatTheTrialNeeds(spec);
  for (const dsl::DroneSpec* d : needs.library_brains) {
    SWARMBOX_TRY(NeedAgentBinary(agent_binary, *d));
    const auto image = AgentWithBrainImage(agent_binary, HostPath(d->brain.host_path, d->brain.path));
    auto r = images::EnsureImage(api, image, progress, nullptr, cache);
    if (!r) return r.error().Context("the agent image of " + d->name + " with its brain library");
    base.drone_agents[d->name] = r->tag;
  }
  for (const dsl::DroneSpec* d : needs.external_brains) {
    auto tag = EnsureUserImage(api, BrainImage(*d), progress, cache);
    if (!tag) return tag.error();
    base.brains[d->name] = *tag;
  }
  for (const dsl::UserComponentSpec& c : spec.components) {
    auto tag = EnsureUserImage(api, ComponentImage(c), progress, cache);
    if (!tag) return tag.error();
    base.components[c.name] = *tag;
  }
  return base;
}

Result<Images> UserImageTags(const dsl::TrialSpec& spec, const std::string& agent_binary, Images base) {
  const Needs needs = WhatTheTrialNeeds(spec);
  for (const dsl::DroneSpec* d : needs.library_brains) {
    SWARMBOX_TRY(NeedAgentBinary(agent_binary, *d));
    auto ctx = images::PackContext(AgentWithBrainImage(agent_binary, HostPath(d->brain.host_path, d->brain.path)));
    if (!ctx) return ctx.error().Context("the agent image of " + d->name);
    base.drone_agents[d->name] = ctx->tag;
  }
  for (const dsl::DroneSpec* d : needs.external_brains) {
    auto tag = UserImageTag(BrainImage(*d));
    if (!tag) return tag.error();
    base.brains[d->name] = *tag;
  }
  for (const dsl::UserComponentSpec& c : spec.components) {
    auto tag = UserImageTag(ComponentImage(c));
    if (!tag) return tag.error();
    base.components[c.name] = *tag;
  }
  return base;
}

}  // namespace swarmbox::runner
