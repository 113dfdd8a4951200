// Loading kernel modules inside the guest without kmod: the module tree's modules.dep says which
// file each module is and what it needs; ModuleLoadOrder puts the wanted modules and everything they
// need in an order the kernel accepts (dependencies first), and LoadModules hands each file to
// finit_module(2).
//
//   auto dep = ReadWholeFile(dir + "/modules.dep");
//   auto order = ModuleLoadOrder(dep, {"sch_netem", "veth"});   // {"kernel/net/sched/sch_netem.ko", ...}
//   if (!order) return order.error();                           // a module the tree does not have
//   SWARMBOX_TRY(LoadModules(dir, *order));                      // already loaded counts as loaded
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::netem_guest {

// The module name of a path in modules.dep: "kernel/net/sched/sch_netem.ko" -> "sch_netem" (a
// compressed .ko.xz / .ko.zst too; '-' read as '_', as the kernel does).
std::string ModuleName(std::string_view path);

// Paths (relative to the module tree, as modules.dep writes them) of `wanted` and their
// dependencies, each once, dependencies before the modules that need them. kNotFound names a
// wanted or needed module that modules.dep does not list; kInvalidArgument a line without ':'.
Result<std::vector<std::string>> ModuleLoadOrder(std::string_view modules_dep,
                                                 const std::vector<std::string>& wanted);

// finit_module(2) of each `dir`/path in order; a module already loaded (EEXIST) is fine. kIo with
// the path and the kernel's reason otherwise. Uncompressed modules only (the guest has no
// decompressor); a compressed one fails with kInvalidArgument.
Status LoadModules(const std::string& dir, const std::vector<std::string>& paths);

}  // namespace swarmbox::netem_guest
