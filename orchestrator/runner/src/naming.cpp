#include "swarmbox/runner/naming.hpp"

#include <chrono>
#include <cstdio>
#include <ctime>
#include <random>

#include "swarmbox/docker/docker_api.hpp"

namespace swarmbox::runner {

std::string MakeRunId(std::int64_t unix_s, std::uint32_t random) {
  std::time_t t = static_cast<std::time_t>(unix_s);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[80];
  std::snprintf(buf, sizeof buf, "%04d%02d%02d-%02d%02d%02d-%04x", tm.tm_year + 1900, tm.tm_mon + 1,
                tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, random & 0xffffu);
  return buf;
}

std::string NewRunId() {
  const auto now = std::chrono::system_clock::now();
  const auto s = std::chrono::duration_cast<std::chrono::seconds>(now.time_since_epoch()).count();
  std::random_device rd;
  return MakeRunId(static_cast<std::int64_t>(s), rd());
}

std::string ResourceName(std::string_view trial, std::string_view run_id,
                         std::string_view component) {
  return std::string(trial) + "-" + std::string(run_id) + "-" + std::string(component);
}

std::string TrialDirName(std::string_view trial, std::string_view run_id) {
  return std::string(trial) + "-" + std::string(run_id);
}

std::map<std::string, std::string> RunLabels(std::string_view run_id, std::string_view trial_id,
                                             std::string_view component) {
  return docker::SwarmboxLabels(run_id, trial_id, component);
}

std::map<std::string, std::string> RoleLabels(std::string_view run_id, std::string_view trial_id,
                                              std::string_view component, std::string_view role) {
  auto labels = RunLabels(run_id, trial_id, component);
  labels[std::string(kLabelRole)] = std::string(role);
  return labels;
}

}  // namespace swarmbox::runner
