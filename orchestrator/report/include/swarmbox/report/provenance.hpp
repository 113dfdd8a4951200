// Provenance: what produced a result, so two runs of one trial can be compared knowing what
// differed. The runner fills it for result.json, `swarmbox experiment` for experiment.json
// (the fields common to its trials, with one engine per host), and results.csv carries it as
// columns after the metrics (ProvenanceColumns). The full resolved trial is trial.yaml. Pure.
//
// As JSON (result.json's "provenance"):
//   {"swarmbox_version":"0.1.0","swarmbox_commit":"1a2b3c4d5e6f","build_type":"RelWithDebInfo",
//    "images":["swarmbox/agent:3f2a...","swarmbox/physics:9c1d..."],
//    "docker_version":"20.10.24+dfsg1","docker_api_version":"1.41","kernel":"6.1.0-18-amd64",
//    "fault_mechanism":"netem","rtf_requested":1,"rtf_achieved":0.97,"host_name":"lab-3"}
// fault_mechanism: "netem" (kernel sch_netem), "userspace-nfqueue" (faults/mechanism.hpp), or
// "none" when the trial impairs no link. rtf_requested: physics.rtf (0 = as fast as possible);
// rtf_achieved: simulated seconds over wall seconds from the first to the last simulated time the
// runner saw. host_name: the machine the orchestrator ran on. A value not known is "" (null for
// the rtfs), never invented.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::report {

struct EngineProvenance {
  std::string docker_version;      // GET /version: Version
  std::string docker_api_version;  // ApiVersion
  std::string kernel;              // KernelVersion
};

struct Provenance {
  std::string swarmbox_version;
  std::string swarmbox_commit;
  std::string build_type;
  std::vector<std::string> images;  // every image reference the trial ran ("repo:<content hash>")
  EngineProvenance engine;
  std::string fault_mechanism;
  std::optional<double> rtf_requested;
  std::optional<double> rtf_achieved;
  std::string host_name;
};

// The swarmbox build (common/version.hpp) and this machine's host name.
Provenance LocalProvenance();

yaml::Node ProvenanceNode(const Provenance& p);
// Reads result.json's "provenance" (missing keys stay empty: folders written before it existed).
Provenance ParseProvenance(const yaml::Node& node);

// results.csv's provenance columns, in order, and a record's cells for them (images joined with
// a space).
const std::vector<std::string>& ProvenanceColumns();
std::vector<std::string> ProvenanceCells(const Provenance& p);

// The host name (gethostname); "" when it cannot be read.
std::string HostName();

}  // namespace swarmbox::report
