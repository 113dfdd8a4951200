#include "guest_console.hpp"

#include <cstdlib>

namespace swarmbox::netem_guest {

std::string GuestRecord::Field(std::string_view key) const { return FindField(fields, key).value_or(""); }

bool GuestConsole::done() const {
  for (const GuestRecord& r : records) {
    if (r.event == kEventDone) return true;
  }
  return false;
}

std::string GuestConsole::Errors() const {
  std::string out;
  for (const GuestRecord& r : records) {
    if (r.event == kEventError) out += r.Field("scenario") + ": " + r.Field("message") + "\n";
  }
  return out;
}

const GuestRecord* GuestConsole::Find(
    std::string_view event, const std::vector<std::pair<std::string_view, std::string_view>>& match) const {
  for (const GuestRecord& r : records) {
    if (r.event != event) continue;
    bool all = true;
    for (const auto& [key, value] : match) {
      auto v = FindField(r.fields, key);
      if (!v || *v != value) {
        all = false;
        break;
      }
    }
    if (all) return &r;
  }
  return nullptr;
}

std::pair<double, std::string> GuestConsole::LongestStall() const {
  std::pair<double, std::string> worst{0.0, ""};
  for (const GuestRecord& r : records) {
    if (r.event != kEventMeasured) continue;
    const std::string late = r.Field("send_late_max_ms");
    if (late.empty()) continue;
    const double ms = std::strtod(late.c_str(), nullptr);
    if (ms > worst.first) worst = {ms, r.Field("probe")};
  }
  return worst;
}

GuestConsole ParseGuestConsole(std::string_view console) {
  GuestConsole out;
  std::size_t start = 0;
  while (start < console.size()) {
    std::size_t end = console.find('\n', start);
    if (end == std::string_view::npos) end = console.size();
    std::string_view line = console.substr(start, end - start);
    start = end + 1;
    while (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    // The record starts at its "t=": a kernel line may have been printed in front of it.
    const std::size_t t = line.find("t=");
    if (t == std::string_view::npos) continue;
    LogfmtFields fields = ParseLogfmt(line.substr(t));
    auto node = FindField(fields, "node");
    auto event = FindField(fields, "event");
    if (!node || *node != kGuestNode || !event) continue;
    out.records.push_back(GuestRecord{*event, std::move(fields)});
  }
  return out;
}

std::string GuestLine(double t_s, std::string_view event,
                      const std::vector<std::pair<std::string, std::string>>& fields) {
  LogEvent line(t_s, kGuestNode, event);
  for (const auto& [key, value] : fields) line.Add(key, value);
  return line.str();
}

}  // namespace swarmbox::netem_guest
