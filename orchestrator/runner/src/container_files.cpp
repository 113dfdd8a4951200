#include "swarmbox/runner/container_files.hpp"

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <utility>

#include "swarmbox/docker/tar_archive.hpp"

namespace swarmbox::runner {

namespace fs = std::filesystem;

namespace {

// The volume a path lies under ("" = none): Docker's archive endpoint writes into a read-only
// container only there ("container rootfs is marked read-only" elsewhere; a tmpfs is not mounted
// before the start, so what is put there is hidden once it runs).
std::string VolumeOf(const dsl::ContainerSpec& spec, const std::string& path) {
  for (const std::string& v : spec.volumes) {
    const std::string prefix = !v.empty() && v.back() == '/' ? v : v + "/";
    if (path.rfind(prefix, 0) == 0) return v;
  }
  return {};
}

// The archives CopyInputs puts into a container: one per destination, "/" for a writable root
// filesystem, else each volume; each with the directories it already holds.
class InputArchives {
 public:
  explicit InputArchives(const dsl::ContainerSpec& spec) : spec_(spec) {}

  // A scratch directory (mode 1777), with its parents.
  Status AddScratchDir(const std::string& dir) {
    std::string relative;
    auto a = ArchiveFor(dir, &relative);
    if (!a) return a.error();
    SWARMBOX_TRY(AddParents(**a, relative));
    if ((*a)->dirs.insert(relative).second) SWARMBOX_TRY((*a)->tar.AddDirectory(relative, 01777));
    return Ok{};
  }

  // An input file read from the host, with its parents.
  Status AddInput(const dsl::InputFile& in) {
    std::ifstream f(in.host_path, std::ios::binary);
    if (!f) return Error(ErrorCode::kNotFound, "cannot read input file", in.host_path);
    std::ostringstream content;
    content << f.rdbuf();
    std::string relative;
    auto a = ArchiveFor(in.container_path, &relative);
    if (!a) return a.error();
    SWARMBOX_TRY(AddParents(**a, relative));
    return (*a)->tar.AddFile(relative, content.str(), 0644);
  }

  Status PutAll(docker::DockerApi& api, const std::string& container_id) {
    for (auto& [dest, a] : archives_) {
      auto bytes = a.tar.Finish();
      if (!bytes) return bytes.error();
      SWARMBOX_TRY(api.PutArchive(container_id, dest, *bytes));
    }
    return Ok{};
  }

 private:
  struct Archive {
    docker::TarWriter tar;
    std::set<std::string> dirs;
  };

  Result<Archive*> ArchiveFor(const std::string& path, std::string* relative) {
    std::string dest = "/";
    if (spec_.read_only_rootfs) {
      dest = VolumeOf(spec_, path);
      if (dest.empty()) {
        return Error(ErrorCode::kInvalidArgument,
                     "the root filesystem is read-only and " + path + " lies in none of its volumes");
      }
    }
    *relative = fs::path(path).lexically_relative(dest).string();
    return &archives_[dest];
  }

  static Status AddParents(Archive& a, const std::string& relative) {
    std::vector<std::string> chain;
    for (fs::path p = fs::path(relative).parent_path(); !p.empty(); p = p.parent_path()) {
      chain.push_back(p.string());
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      if (a.dirs.insert(*it).second) SWARMBOX_TRY(a.tar.AddDirectory(*it, 0755));
    }
    return Ok{};
  }

  const dsl::ContainerSpec& spec_;
  std::map<std::string, Archive> archives_;
};

// Where CollectArtifacts writes one container's artifacts, and what it collected.
struct ArtifactSink {
  const std::string& component;
  const std::string& trial_dir;
  const std::string& artifacts_dir;
  fs::path dest_dir;
  CollectedArtifacts collected;

  void Problem(std::string text) { collected.problems.push_back(component + ": " + std::move(text)); }

  // One file of an artifact's archive: the trial folder keeps file names (truth.csv); an
  // artifacts_dir keeps a folder's layout. Paths leaving the folder are skipped.
  void Write(const docker::TarEntry& e) {
    const fs::path relative = fs::path(e.path).lexically_normal();
    if (relative.empty() || relative.is_absolute() || *relative.begin() == "..") return;
    const std::string name = artifacts_dir.empty() ? relative.filename().string()
                                                   : (fs::path(artifacts_dir) / relative).string();
    if (!artifacts_dir.empty() && relative.has_parent_path()) {
      std::error_code ec;
      fs::create_directories(dest_dir / relative.parent_path(), ec);
    }
    const std::string dest = artifacts_dir.empty() ? (fs::path(trial_dir) / name).string()
                                                   : (dest_dir / relative).string();
    std::ofstream out(dest, std::ios::binary | std::ios::trunc);
    out.write(e.content.data(), static_cast<std::streamsize>(e.content.size()));
    if (!out) {
      Problem("cannot write " + dest);
      return;
    }
    collected.files[name] = dest;
  }
};

}  // namespace

Status CopyInputs(docker::DockerApi& api, const dsl::ContainerSpec& spec,
                  const std::string& container_id) {
  if (spec.inputs.empty() && spec.scratch_dirs.empty()) return Ok{};
  InputArchives archives(spec);
  for (const std::string& dir : spec.scratch_dirs) SWARMBOX_TRY(archives.AddScratchDir(dir));
  for (const dsl::InputFile& in : spec.inputs) SWARMBOX_TRY(archives.AddInput(in));
  return archives.PutAll(api, container_id);
}

CollectedArtifacts CollectArtifacts(docker::DockerApi& api, const std::string& container_id,
                                    const std::string& component,
                                    const std::vector<std::string>& artifacts,
                                    const std::string& trial_dir, const std::string& artifacts_dir) {
  ArtifactSink sink{component, trial_dir, artifacts_dir, fs::path(trial_dir) / artifacts_dir, {}};
  if (!artifacts_dir.empty() && !artifacts.empty()) {
    std::error_code ec;
    fs::create_directories(sink.dest_dir, ec);
    if (ec) {
      sink.Problem("cannot create " + sink.dest_dir.string() + ": " + ec.message());
      return std::move(sink.collected);
    }
  }
  for (const std::string& path : artifacts) {
    auto tar = api.GetArchive(container_id, path);
    if (!tar) {
      sink.Problem("artifact " + path + " not collected: " + tar.error().ToString());
      continue;
    }
    auto entries = docker::ReadTar(*tar);
    if (!entries) {
      sink.Problem("artifact " + path + " unreadable: " + entries.error().ToString());
      continue;
    }
    for (const docker::TarEntry& e : *entries) {
      if (e.type == docker::TarEntry::Type::kFile) sink.Write(e);
    }
  }
  return std::move(sink.collected);
}

}  // namespace swarmbox::runner
