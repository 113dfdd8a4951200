// Parsing the loader's list of a program's shared-library closure (pure).
//
// `/lib64/ld-linux-x86-64.so.2 --list PROGRAM` (what ldd runs) prints one library per line:
//   	linux-vdso.so.1 (0x00007ffd...)                          kernel-provided: skipped
//   	libc.so.6 => /lib/x86_64-linux-gnu/libc.so.6 (0x...)    name => resolved path
//   	/lib64/ld-linux-x86-64.so.2 (0x...)                      the loader itself
//   	libfoo.so.1 => not found                                  unresolved
// The list is already transitive and follows RUNPATH/RPATH, LD_LIBRARY_PATH and ld.so.cache.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::images {

struct LdListEntry {
  std::string name;  // as needed ("libc.so.6"), or the path for the loader line
  std::string path;  // absolute resolved path; "" when not found
};

// Entries in output order, kernel-provided ones (no path, no "=>") left out. A line saying
// "not found" gives an entry with an empty path; the caller decides. Lines that fit no known shape
// are kProtocol errors quoting the line.
Result<std::vector<LdListEntry>> ParseLdList(std::string_view output);

}  // namespace swarmbox::images
