// The shared-library closure of ELF programs and plugins: every file the loader maps to run them,
// the ELF interpreter included, by the absolute paths it resolves them to (RUNPATH/RPATH,
// ld.so.cache, default directories, as on this host).
//
//   auto files = SharedLibraryClosure({"/usr/sbin/tc", "/usr/lib/x86_64-linux-gnu/xtables/libxt_statistic.so"});
//   // {"/lib64/ld-linux-x86-64.so.2", "/lib/x86_64-linux-gnu/libbpf.so.1", ...}
//
// Each file's interpreter comes from its PT_INTERP (read from the ELF itself); plugins and other
// shared objects without one use the interpreter of the programs in the same call. The loader is
// then run as `<interpreter> --list <file>` (posix_spawn, argv array) and its answer parsed
// (ld_list.hpp). Static programs add nothing. Errors: a library the loader cannot find is
// kNotFound naming it and who needs it; unreadable or non-ELF inputs are kInvalidArgument.
#pragma once

#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::images {

// The sorted, de-duplicated closure (the inputs themselves not included).
Result<std::vector<std::string>> SharedLibraryClosure(const std::vector<std::string>& elf_paths);

// Reads a whole file (following symlinks). kNotFound / kIo with where = path.
Result<std::string> ReadFileBytes(const std::string& path);

}  // namespace swarmbox::images
