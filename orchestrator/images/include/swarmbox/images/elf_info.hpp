// Reading what an ELF file needs at load time, from its bytes (pure; no I/O, no exec).
//
//   ElfInfo info = *ReadElfInfo(file_bytes, "/usr/bin/swarmbox-agent");
//   info.interpreter   // "/lib64/ld-linux-x86-64.so.2" (PT_INTERP), "" for static or .so
//   info.needed        // {"libstdc++.so.6", "libc.so.6", ...} (DT_NEEDED, in file order)
//   info.runpath       // DT_RUNPATH entries split at ':' (DT_RPATH in `rpath`)
//
// The image packer uses it to find a program's loader and to know whether a file is a dynamic
// ELF at all; the search for the libraries themselves is left to the loader (library_closure.hpp).
// Supports ELF32/ELF64, little and big endian. Malformed input is kInvalidArgument naming `what`.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::images {

struct ElfInfo {
  enum class Kind { kExecutable, kSharedObject, kOther };
  Kind kind = Kind::kOther;
  bool is_64 = false;
  std::uint16_t machine = 0;     // e_machine, 62 = x86-64, 183 = AArch64
  std::string interpreter;       // PT_INTERP, "" when none
  std::vector<std::string> needed;
  std::vector<std::string> runpath;
  std::vector<std::string> rpath;
  std::string soname;
  bool dynamic = false;          // has a PT_DYNAMIC segment
};

// True when the bytes start with the ELF magic.
bool LooksLikeElf(std::string_view bytes);

// `what` names the file in errors.
Result<ElfInfo> ReadElfInfo(std::string_view bytes, std::string_view what);

}  // namespace swarmbox::images
