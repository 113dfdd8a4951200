// Names and labels of everything a run creates, so parallel trials on one host never collide and
// `swarmbox gc` finds what a killed orchestrator left (ARCHITECTURE.md "Labels", contract).
//
//   run id            20261121-131210-7f3a        UTC start time + 16 random bits
//   Docker names      <trial>-<run id>-<component> sar-search-20261121-131210-7f3a-scout_1
//   output folder     <out>/<trial>-<run id>/      runs/sar-search-20261121-131210-7f3a/
//   labels            swarmbox.run=<run id> swarmbox.trial=<trial id> swarmbox.component=<name>
//                     + swarmbox.role=brain|component on a drone's external brain and a user's
//                     component (the trial's `components:`), so tools can tell them apart
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>

namespace swarmbox::runner {

// Pure: `unix_s` is the UTC start time, `random` supplies the 16 random bits.
std::string MakeRunId(std::int64_t unix_s, std::uint32_t random);
// MakeRunId(now, std::random_device).
std::string NewRunId();

std::string ResourceName(std::string_view trial, std::string_view run_id,
                         std::string_view component);
std::string TrialDirName(std::string_view trial, std::string_view run_id);

std::map<std::string, std::string> RunLabels(std::string_view run_id, std::string_view trial_id,
                                             std::string_view component);

inline constexpr std::string_view kLabelRole = "swarmbox.role";
inline constexpr std::string_view kRoleBrain = "brain";
inline constexpr std::string_view kRoleComponent = "component";
// RunLabels plus swarmbox.role=<role>.
std::map<std::string, std::string> RoleLabels(std::string_view run_id, std::string_view trial_id,
                                              std::string_view component, std::string_view role);

}  // namespace swarmbox::runner
