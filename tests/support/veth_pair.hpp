// VethPair: two network namespaces joined by a veth pair, an IPv4 address (/24) on each end and
// the links up, for tests that shape and measure traffic between two network stacks (the
// userspace netem e2e test, the Raft reordering test). Needs root (CAP_SYS_ADMIN, CAP_NET_ADMIN).
// Library swarmbox_netns_test_support (links swarmbox::faults_model for CommandRunner).
//
//   faults::PosixCommandRunner runner;
//   VethPair pair(runner);
//   Status s = pair.Create({"sbf", "swarmbox-faults-e2e", "10.213.7.1", "10.213.7.2", false, netemd});
//   ASSERT_TRUE(s) << s.error().ToString();       // "`ip netns add ...` failed: <stderr>"
//   ... pair.ns_a, pair.if_a, pair.dir / "a" (a scratch folder per side, e.g. netemd's pidfiles)
//   pair.Remove();                                 // also the destructor
#pragma once

#include <filesystem>
#include <string>

#include "swarmbox/common/result.hpp"
#include "swarmbox/faults/command_runner.hpp"

namespace swarmbox::testing {

class VethPair {
 public:
  struct Options {
    // Names carry this process's pid: namespaces <prefix>-<pid>-a and -b, interfaces
    // <prefix>a<pid> and <prefix>b<pid>, scratch folder <tmp>/<scratch>-<pid> with a/ and b/.
    std::string prefix;
    std::string scratch;
    std::string addr_a;  // IPv4 of the a end (/24)
    std::string addr_b;
    bool loopback_up = false;  // bring each namespace's lo up too (as in a container)
    // swarmbox-netemd: Remove() first stops the daemons whose pidfiles are in a/ and b/ ("" = none).
    std::string netemd;
  };

  explicit VethPair(faults::CommandRunner& runner) : runner_(runner) {}
  ~VethPair() { Remove(); }
  VethPair(const VethPair&) = delete;
  VethPair& operator=(const VethPair&) = delete;

  // Creates the scratch folders, the namespaces, the pair and its addresses; the first command
  // that fails is the error ("`<argv>` failed: <stderr>"). Remove() takes down what was made.
  Status Create(const Options& options);
  // Best effort, every path (daemons by their pidfiles, the namespaces with their veth ends and
  // rules, the scratch folder); idempotent.
  void Remove();

  std::string ns_a, ns_b, if_a, if_b;
  std::filesystem::path dir;

 private:
  Status Must(const std::vector<std::string>& argv);

  faults::CommandRunner& runner_;
  std::string netemd_;
  bool created_ = false;
};

}  // namespace swarmbox::testing
