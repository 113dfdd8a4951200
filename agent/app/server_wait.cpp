#include "server_wait.hpp"

#include <cstdio>
#include <string_view>

namespace swarmbox::agent {
namespace {

std::string_view Field(const bus::Event& e, std::string_view key) {
  for (const bus::KeyValue& kv : e.fields) {
    if (kv.key == key) return kv.value;
  }
  return {};
}

std::uint64_t Number(std::string_view s) {
  std::uint64_t v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return 0;
    v = v * 10 + static_cast<std::uint64_t>(c - '0');
  }
  return v;
}

bool Lists(std::string_view names, std::string_view drone) {
  while (!names.empty()) {
    const std::size_t comma = names.find(',');
    if (names.substr(0, comma) == drone) return true;
    if (comma == std::string_view::npos) break;
    names.remove_prefix(comma + 1);
  }
  return false;
}

std::string Seconds(std::chrono::milliseconds ms) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", static_cast<double>(ms.count()) / 1000.0);
  return buf;
}

}  // namespace

void ServerWait::OnStatus(const bus::Event& status) {
  ++statuses_;
  budget_ = WaitBudget(timeout_);
  joined_ = Number(Field(status, "joined"));
  expected_ = Number(Field(status, "expected"));
  listed_ = Lists(Field(status, "missing"), drone_);
  // The start is over and this drone was not waited for: no sample will come (a drone the server
  // does not know). A drone lost at the start still gets samples (it may rejoin): keep waiting.
  if (status.name == "joined" && !listed_) left_out_ = true;
}

std::string ServerWait::Reason() const {
  if (statuses_ == 0)
    return "within " + Seconds(timeout_) + " s and no sign of the physics server (sim/status)";
  const std::string start = "joined " + std::to_string(joined_) + "/" + std::to_string(expected_);
  if (left_out_) return "and the physics server started without this drone (" + start + ")";
  return "for " + Seconds(timeout_) + " s after the physics server's last status (" + start +
         (listed_ ? ", this drone missing)" : ")");
}

}  // namespace swarmbox::agent
