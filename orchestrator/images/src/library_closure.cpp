#include "swarmbox/images/library_closure.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "swarmbox/images/elf_info.hpp"
#include "swarmbox/images/ld_list.hpp"
#include "swarmbox/images/process_capture.hpp"

namespace swarmbox::images {

Result<std::string> ReadFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int e = errno;
    return Error(e == ENOENT ? ErrorCode::kNotFound : ErrorCode::kIo,
                 std::string("cannot read: ") + std::strerror(e), path);
  }
  std::ostringstream out;
  out << in.rdbuf();
  if (in.bad()) return Error(ErrorCode::kIo, "read failed", path);
  return out.str();
}

Result<std::vector<std::string>> SharedLibraryClosure(const std::vector<std::string>& elf_paths) {
  struct Input {
    std::string path;
    ElfInfo info;
  };
  std::vector<Input> inputs;
  std::string shared_interpreter;
  for (const std::string& path : elf_paths) {
    auto bytes = ReadFileBytes(path);
    if (!bytes) return bytes.error();
    auto info = ReadElfInfo(*bytes, path);
    if (!info) return info.error();
    if (shared_interpreter.empty() && !info->interpreter.empty()) {
      shared_interpreter = info->interpreter;
    }
    inputs.push_back({path, std::move(*info)});
  }

  std::set<std::string> closure;
  for (const Input& in : inputs) {
    if (!in.info.dynamic) continue;  // static: needs nothing
    const std::string interpreter =
        !in.info.interpreter.empty() ? in.info.interpreter : shared_interpreter;
    if (interpreter.empty()) {
      return Error(ErrorCode::kInvalidArgument,
                   "a shared object without an ELF interpreter needs a program in the same image "
                   "to say which loader runs it",
                   in.path);
    }
    closure.insert(interpreter);
    auto run = RunCapture({interpreter, "--list", in.path});
    if (!run) return run.error().Context("listing the libraries of " + in.path);
    if (run->exit_code != 0) {
      return Error(ErrorCode::kInvalidArgument,
                   "the loader cannot list its libraries (exit " + std::to_string(run->exit_code) +
                       "): " + run->err + run->out,
                   in.path);
    }
    auto entries = ParseLdList(run->out);
    if (!entries) return Error(entries.error().code(), entries.error().message(), in.path);
    for (const LdListEntry& e : *entries) {
      if (e.path.empty()) {
        return Error(ErrorCode::kNotFound,
                     "needs " + e.name + ", which the loader cannot find on this host", in.path);
      }
      closure.insert(e.path);
    }
  }
  return std::vector<std::string>(closure.begin(), closure.end());
}

}  // namespace swarmbox::images
