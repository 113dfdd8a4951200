// ImageSpec: what goes into a registry-free `FROM scratch` image (ARCHITECTURE.md "Images without
// a registry"). The packer (image_context.hpp) adds the shared-library closure of every ELF it
// lists, builds a deterministic tar context with a generated Dockerfile, and names the image by the
// content hash of that context; EnsureImage (ensure_image.hpp) builds it only when the engine does
// not have that tag yet.
//
//   ImageSpec spec;
//   spec.repository = "swarmbox/physics";
//   spec.component = "physics";
//   spec.executables = {{"/work/main/build/physics_server/swarmbox-physics",
//                        "/usr/local/bin/swarmbox-physics"}};
//   spec.entrypoint = {"/usr/local/bin/swarmbox-physics"};
//   AddSwarmboxBaseFiles(&spec);   // /etc/passwd and /etc/group with uid 1000 `swarmbox`, /tmp
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::images {

// The non-root user every SwarmBox container runs as.
inline constexpr int kSwarmboxUid = 1000;
inline constexpr int kSwarmboxGid = 1000;

struct HostFile {
  std::string host_path;   // read from here on the build host (symlinks followed)
  std::string image_path;  // absolute path inside the image
  std::uint32_t mode = 0;  // permission bits; 0 = the host file's
};

struct ImageSpec {
  std::string repository;  // "swarmbox/physics"; the tag is the context's content hash
  std::string component;   // value of the image's swarmbox.component label
  std::vector<HostFile> executables;  // ELF programs: their library closure comes along
  std::vector<HostFile> plugins;      // ELF objects loaded at run time (dlopen): closure too
  std::vector<HostFile> files;        // other host files, copied as they are
  std::map<std::string, std::string> inline_files;   // image path -> content (mode 0644)
  std::map<std::string, std::string> symlinks;       // image path -> link target
  std::map<std::string, std::uint32_t> directories;  // image path -> mode, e.g. "/tmp" -> 01777
  std::vector<std::string> entrypoint;
  std::vector<std::string> cmd;
  std::map<std::string, std::string> env;
  std::string user = "1000:1000";
  std::string workdir;  // "" = "/" (each Dockerfile instruction costs a builder step)
  std::map<std::string, std::string> labels;  // extra image labels
  // Strip debug sections from `executables` (`objcopy --strip-debug`, binutils): a RelWithDebInfo
  // swarmbox-physics drops from ~23 MB to ~1.5 MB. Libraries from the host are left as they are.
  bool strip_debug = true;
};

// /etc/passwd and /etc/group (root, swarmbox uid/gid 1000, nobody; from docker/rootfs/etc/ in the
// source tree, compiled in), and /tmp (1777).
void AddSwarmboxBaseFiles(ImageSpec* spec);

// Every regular file in `host_dir` whose name ends in `suffix` (e.g. iptables' run-time plugins
// "/usr/lib/x86_64-linux-gnu/xtables/*.so", which ldd does not list) as plugins under `image_dir`,
// in name order. kNotFound when the directory does not exist or holds no such file.
Status AddPluginDirectory(ImageSpec* spec, const std::string& host_dir, const std::string& image_dir,
                          const std::string& suffix);

}  // namespace swarmbox::images
