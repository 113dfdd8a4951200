#include "swarmbox/experiment/progress.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace swarmbox::experiment {

std::string FormatDuration(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char buf[32];
  if (s >= 3600) {
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", s / 3600, (s % 3600) / 60);
  } else if (s >= 60) {
    std::snprintf(buf, sizeof buf, "%ldm%02lds", s / 60, s % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%lds", s);
  }
  return buf;
}

ProgressBoard::ProgressBoard(std::vector<std::pair<std::string, int>> hosts, std::size_t total,
                             std::size_t done_before)
    : total_(total), done_(done_before) {
  for (auto& [name, slots] : hosts) {
    HostRow row;
    row.name = name;
    row.slots = slots;
    hosts_.push_back(std::move(row));
  }
}

ProgressBoard::HostRow* ProgressBoard::Find(const std::string& host) {
  for (HostRow& h : hosts_) {
    if (h.name == host) return &h;
  }
  return nullptr;
}

void ProgressBoard::Started(const std::string& host, const std::string& trial, double now_s) {
  if (HostRow* h = Find(host)) h->running[trial] = now_s;
}

void ProgressBoard::Finished(const std::string& host, const std::string& trial,
                             const std::string& outcome, double now_s) {
  HostRow* h = Find(host);
  if (h == nullptr) return;
  auto it = h->running.find(trial);
  const double started = it == h->running.end() ? now_s : it->second;
  if (it != h->running.end()) h->running.erase(it);
  if (outcome.empty()) {
    ++requeued_;
    return;
  }
  ++h->done;
  ++done_;
  outcomes_[outcome] += 1;
  wall_sum_s_ += now_s - started;
  ++wall_n_;
}

void ProgressBoard::HostDown(const std::string& host, const std::string& reason) {
  if (HostRow* h = Find(host)) {
    h->up = false;
    h->reason = reason;
  }
}

void ProgressBoard::Exhausted(const std::string& /*trial*/) {
  // The trial ends with outcome error (counted like any finished trial).
  ++done_;
  outcomes_["error"] += 1;
  if (requeued_ > 0) --requeued_;
}

std::string ProgressBoard::HostLine(const HostRow& h, std::size_t width, double now_s) const {
  std::string line = h.name + std::string(width - h.name.size() + 2, ' ');
  line += std::to_string(h.slots) + (h.slots == 1 ? " slot   " : " slots  ");
  line += h.up ? "up    " : "DOWN  ";
  line += "done " + std::to_string(h.done);
  if (!h.running.empty()) {
    line += "  running";
    bool first = true;
    for (const auto& [trial, t0] : h.running) {
      line += (first ? " " : ", ") + trial + " " + FormatDuration(now_s - t0);
      first = false;
    }
  }
  if (!h.up) line += "  (" + h.reason.substr(0, kReasonChars) + ")";
  return line;
}

std::string ProgressBoard::SummaryLine(std::size_t running, int slots_up) const {
  const double frac = total_ == 0 ? 1.0 : static_cast<double>(done_) / static_cast<double>(total_);
  const int filled = static_cast<int>(std::floor(frac * kBarChars));
  std::string bar = "[" + std::string(static_cast<std::size_t>(filled), '#') +
                    std::string(static_cast<std::size_t>(kBarChars - filled), '.') + "] " +
                    std::to_string(done_) + "/" + std::to_string(total_) + " ";
  for (const char* o : {"success", "failure", "timeout", "error"}) {
    auto it = outcomes_.find(o);
    bar += " " + std::string(o) + " " + std::to_string(it == outcomes_.end() ? 0 : it->second);
  }
  bar += " | running " + std::to_string(running);
  if (requeued_ > 0) bar += " | requeued " + std::to_string(requeued_);
  const std::size_t left = total_ > done_ ? total_ - done_ : 0;
  if (left == 0) {
    bar += " | done";
  } else if (wall_n_ == 0 || slots_up == 0) {
    bar += " | ETA ?";
  } else {
    const double mean = wall_sum_s_ / static_cast<double>(wall_n_);
    const double waves = std::ceil(static_cast<double>(left) / slots_up);
    bar += " | ETA " + FormatDuration(waves * mean);
  }
  return bar;
}

std::vector<std::string> ProgressBoard::Render(double now_s) const {
  std::vector<std::string> lines;
  std::size_t width = 4;
  for (const HostRow& h : hosts_) width = std::max(width, h.name.size());
  std::size_t running = 0;
  int slots_up = 0;
  for (const HostRow& h : hosts_) {
    lines.push_back(HostLine(h, width, now_s));
    running += h.running.size();
    if (h.up) slots_up += h.slots;
  }
  lines.push_back(SummaryLine(running, slots_up));
  return lines;
}

}  // namespace swarmbox::experiment
