#include "support/veth_pair.hpp"

#include <unistd.h>

#include <system_error>
#include <vector>

namespace swarmbox::testing {

Status VethPair::Must(const std::vector<std::string>& argv) {
  auto out = runner_.Run(argv);
  if (!out) return out.error();
  if (out->exit_code != 0) {
    return Error(ErrorCode::kInternal,
                 "`" + faults::CommandText(argv) + "` failed: " + out->stderr_text);
  }
  return Ok{};
}

Status VethPair::Create(const Options& o) {
  const std::string tag = std::to_string(::getpid());
  ns_a = o.prefix + "-" + tag + "-a";
  ns_b = o.prefix + "-" + tag + "-b";
  if_a = o.prefix + "a" + tag;
  if_b = o.prefix + "b" + tag;
  dir = std::filesystem::temp_directory_path() / (o.scratch + "-" + tag);
  netemd_ = o.netemd;
  std::filesystem::create_directories(dir / "a");
  std::filesystem::create_directories(dir / "b");
  created_ = true;
  SWARMBOX_TRY(Must({"ip", "netns", "add", ns_a}));
  SWARMBOX_TRY(Must({"ip", "netns", "add", ns_b}));
  SWARMBOX_TRY(Must({"ip", "link", "add", if_a, "netns", ns_a, "type", "veth", "peer", "name", if_b,
                     "netns", ns_b}));
  SWARMBOX_TRY(Must({"ip", "-n", ns_a, "addr", "add", o.addr_a + "/24", "dev", if_a}));
  SWARMBOX_TRY(Must({"ip", "-n", ns_b, "addr", "add", o.addr_b + "/24", "dev", if_b}));
  SWARMBOX_TRY(Must({"ip", "-n", ns_a, "link", "set", if_a, "up"}));
  SWARMBOX_TRY(Must({"ip", "-n", ns_b, "link", "set", if_b, "up"}));
  if (o.loopback_up) {
    SWARMBOX_TRY(Must({"ip", "-n", ns_a, "link", "set", "lo", "up"}));
    SWARMBOX_TRY(Must({"ip", "-n", ns_b, "link", "set", "lo", "up"}));
  }
  return Ok{};
}

void VethPair::Remove() {
  if (!created_) return;
  created_ = false;
  if (!netemd_.empty()) {
    for (const char* side : {"a", "b"}) {
      std::error_code ec;
      for (const auto& entry : std::filesystem::directory_iterator(dir / side, ec)) {
        (void)runner_.Run({netemd_, "stop", "--pidfile", entry.path().string()});
      }
    }
  }
  (void)runner_.Run({"ip", "netns", "del", ns_a});
  (void)runner_.Run({"ip", "netns", "del", ns_b});
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}

}  // namespace swarmbox::testing
