#include "kernel_modules.hpp"

#include <fcntl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <functional>
#include <map>
#include <set>
#include <sstream>

namespace swarmbox::netem_guest {

std::string ModuleName(std::string_view path) {
  const std::size_t slash = path.rfind('/');
  std::string_view base = slash == std::string_view::npos ? path : path.substr(slash + 1);
  const std::size_t ko = base.find(".ko");
  if (ko != std::string_view::npos) base = base.substr(0, ko);
  std::string name(base);
  for (char& c : name) {
    if (c == '-') c = '_';
  }
  return name;
}

Result<std::vector<std::string>> ModuleLoadOrder(std::string_view modules_dep,
                                                 const std::vector<std::string>& wanted) {
  // name -> (path, the paths it needs)
  std::map<std::string, std::pair<std::string, std::vector<std::string>>> modules;
  std::istringstream lines{std::string(modules_dep)};
  int line_no = 0;
  for (std::string line; std::getline(lines, line);) {
    ++line_no;
    if (line.empty()) continue;
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) {
      return Error(ErrorCode::kInvalidArgument,
                   "modules.dep line " + std::to_string(line_no) + " has no ':'");
    }
    const std::string path = line.substr(0, colon);
    std::istringstream deps(line.substr(colon + 1));
    std::vector<std::string> needs;
    for (std::string dep; deps >> dep;) needs.push_back(dep);
    modules[ModuleName(path)] = {path, std::move(needs)};
  }

  std::vector<std::string> order;
  std::set<std::string> placed;
  // modules.dep already lists the whole closure on each line (depmod's format), but a module's own
  // needs are placed first anyway, so a hand-written or partial line still loads in a valid order.
  std::function<Status(const std::string&, const std::string&, int)> place =
      [&](const std::string& name, const std::string& needed_by, int depth) -> Status {
    if (placed.count(name) != 0) return Ok{};
    auto it = modules.find(name);
    if (it == modules.end()) {
      return Error(ErrorCode::kNotFound, "module " + name +
                                             (needed_by.empty() ? "" : " (needed by " + needed_by + ")") +
                                             " is not in modules.dep");
    }
    if (depth > 64)
      return Error(ErrorCode::kInvalidArgument, "modules.dep: dependency cycle through " + name);
    for (const std::string& dep : it->second.second) SWARMBOX_TRY(place(ModuleName(dep), name, depth + 1));
    placed.insert(name);
    order.push_back(it->second.first);
    return Ok{};
  };
  for (const std::string& name : wanted) SWARMBOX_TRY(place(ModuleName(name), "", 0));
  return order;
}

Status LoadModules(const std::string& dir, const std::vector<std::string>& paths) {
  for (const std::string& rel : paths) {
    const std::string path = dir + "/" + rel;
    if (path.size() < 3 || path.compare(path.size() - 3, 3, ".ko") != 0) {
      return Error(ErrorCode::kInvalidArgument,
                   "compressed module " + path + ": the guest loads plain .ko files only");
    }
    const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return Error(ErrorCode::kIo, std::string("open: ") + std::strerror(errno), path);
    const long rc = syscall(SYS_finit_module, fd, "", 0);
    const int err = errno;
    close(fd);
    if (rc != 0 && err != EEXIST) {
      return Error(ErrorCode::kIo, std::string("finit_module: ") + std::strerror(err), path);
    }
  }
  return Ok{};
}

}  // namespace swarmbox::netem_guest
