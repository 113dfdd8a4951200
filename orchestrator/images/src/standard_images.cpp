#include "swarmbox/images/standard_images.hpp"

#include <unistd.h>

namespace swarmbox::images {
namespace {

ImageSpec ProgramImage(const std::string& repository, const std::string& component,
                       const std::string& binary, const std::string& in_image) {
  ImageSpec spec;
  spec.repository = repository;
  spec.component = component;
  spec.executables.push_back(HostFile{binary, in_image, 0755});
  spec.entrypoint = {in_image};
  AddSwarmboxBaseFiles(&spec);
  return spec;
}

}  // namespace

ImageSpec PhysicsImage(const std::string& binary) {
  return ProgramImage(kPhysicsRepository, "physics", binary, kPhysicsBinaryInImage);
}

ImageSpec AgentImage(const std::string& binary) {
  return ProgramImage(kAgentRepository, "agent", binary, kAgentBinaryInImage);
}

Result<ImageSpec> FaultToolsImage(const FaultToolPaths& paths) {
  for (const std::string* tool : {&paths.tc, &paths.xtables_multi}) {
    if (access(tool->c_str(), X_OK) != 0) {
      return Error(ErrorCode::kNotFound, "fault tool missing on this host (install iproute2 and iptables)",
                   *tool);
    }
  }
  ImageSpec spec;
  spec.repository = kFaultsRepository;
  spec.component = "faults";
  spec.executables.push_back(HostFile{paths.tc, "/usr/sbin/tc", 0755});
  spec.executables.push_back(HostFile{paths.xtables_multi, "/usr/sbin/xtables-nft-multi", 0755});
  for (const HostFile& program : paths.extra_programs) spec.executables.push_back(program);
  for (const char* link : {"iptables", "iptables-save", "iptables-restore", "ip6tables",
                           "ip6tables-save", "ip6tables-restore"}) {
    spec.symlinks[std::string("/usr/sbin/") + link] = "xtables-nft-multi";
  }
  // iptables loads its matches and targets (statistic, NFQUEUE, ...) from here at run time.
  if (auto s = AddPluginDirectory(&spec, paths.xtables_plugin_dir, "/usr/lib/x86_64-linux-gnu/xtables", ".so");
      !s) {
    return s.error().Context("iptables plugins");
  }
  spec.directories["/run"] = 01777;
  spec.env["PATH"] = "/usr/sbin:/usr/bin:/sbin:/bin";
  AddSwarmboxBaseFiles(&spec);
  spec.user = "0:0";  // see the header: NET_ADMIN cannot reach a non-root user on Docker 20.10
  return spec;
}

Result<ImageSpec> FaultSidecarImage(const std::string& netemd_binary, FaultToolPaths paths) {
  if (access(netemd_binary.c_str(), X_OK) != 0) {
    return Error(ErrorCode::kNotFound, "swarmbox-netemd is not an executable file (build it: target swarmbox-netemd)",
                 netemd_binary);
  }
  paths.extra_programs.push_back(HostFile{netemd_binary, kNetemdInImage, 0755});
  return FaultToolsImage(paths);
}

}  // namespace swarmbox::images
