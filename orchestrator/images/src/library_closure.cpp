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

namespace {

struct ElfInput {
  std::string path;
  ElfInfo info;
};

// Each file's ELF header read; *shared_interpreter: the first interpreter any of them names.
Result<std::vector<ElfInput>> ReadElfInputs(const std::vector<std::string>& elf_paths,
                                            std::string* shared_interpreter) {
  std::vector<ElfInput> inputs;
  for (const std::string& path : elf_paths) {
    auto bytes = ReadFileBytes(path);
    if (!bytes) return bytes.error();
    auto info = ReadElfInfo(*bytes, path);
    if (!info) return info.error();
    if (shared_interpreter->empty() && !info->interpreter.empty()) {
      *shared_interpreter = info->interpreter;
    }
    inputs.push_back({path, std::move(*info)});
  }
  return inputs;
}

// The libraries `interpreter --list path` names (each must be found on this host).
Result<std::vector<std::string>> ListLibraries(const std::string& interpreter, const std::string& path) {
  auto run = RunCapture({interpreter, "--list", path});
  if (!run) return run.error().Context("listing the libraries of " + path);
  if (run->exit_code != 0) {
    return Error(ErrorCode::kInvalidArgument,
                 "the loader cannot list its libraries (exit " + std::to_string(run->exit_code) +
                     "): " + run->err + run->out,
                 path);
  }
  auto entries = ParseLdList(run->out);
  if (!entries) return Error(entries.error().code(), entries.error().message(), path);
  std::vector<std::string> libraries;
  for (const LdListEntry& e : *entries) {
    if (e.path.empty()) {
      return Error(ErrorCode::kNotFound, "needs " + e.name + ", which the loader cannot find on this host", path);
    }
    libraries.push_back(e.path);
  }
  return libraries;
}

}  // namespace

Result<std::vector<std::string>> SharedLibraryClosure(const std::vector<std::string>& elf_paths) {
  std::string shared_interpreter;
  auto inputs = ReadElfInputs(elf_paths, &shared_interpreter);
  if (!inputs) return inputs.error();
  std::set<std::string> closure;
  for (const ElfInput& in : *inputs) {
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
    auto libraries = ListLibraries(interpreter, in.path);
    if (!libraries) return libraries.error();
    closure.insert(libraries->begin(), libraries->end());
  }
  return std::vector<std::string>(closure.begin(), closure.end());
}

}  // namespace swarmbox::images
