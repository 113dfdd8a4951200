// The live progress of an experiment on stderr: one line per host and an overall bar.
//
//   local              2 slots  up    done 3  running radio-ab-r1 12s, radio-ba-r1 3s
//   root@10.250.0.2    1 slot   DOWN  done 1  (dockerd gone: ...)
//   [########............] 4/8  success 3 failure 0 timeout 1 error 0 | running 2 | requeued 1 | ETA 1m40s
//
// ProgressBoard is pure (state + Render(now)); thread-safety is the caller's (ExperimentRunner
// serialises the scheduler's callbacks). ETA = trials left x mean wall time of the trials finished
// in this session / slots up; "?" until one has finished.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace swarmbox::experiment {

class ProgressBoard {
 public:
  // `done_before`: trials committed by an earlier run (--resume) that count as done.
  ProgressBoard(std::vector<std::pair<std::string, int>> hosts, std::size_t total,
                std::size_t done_before);

  void Started(const std::string& host, const std::string& trial, double now_s);
  // outcome: success|failure|timeout|error when the trial ended; "" when the attempt was lost
  // (host failure: it goes back to the queue) or cancelled.
  void Finished(const std::string& host, const std::string& trial, const std::string& outcome,
                double now_s);
  void HostDown(const std::string& host, const std::string& reason);
  void Exhausted(const std::string& trial);

  std::vector<std::string> Render(double now_s) const;
  std::size_t done() const { return done_; }

 private:
  struct HostRow {
    std::string name;
    int slots = 1;
    bool up = true;
    std::string reason;
    std::size_t done = 0;
    std::map<std::string, double> running;  // trial -> start time [s]
  };
  HostRow* Find(const std::string& host);
  // One host's row ("local  4 slots  up    done 3  running e1-001 12s"), its name padded to
  // `width`, and the last row: the bar, the outcomes, the running count and the ETA.
  std::string HostLine(const HostRow& h, std::size_t width, double now_s) const;
  std::string SummaryLine(std::size_t running, int slots_up) const;
  static constexpr int kBarChars = 20;              // the progress bar's width
  static constexpr std::size_t kReasonChars = 160;  // a down host's reason, cut to this

  std::vector<HostRow> hosts_;
  std::size_t total_;
  std::size_t done_;
  std::map<std::string, std::size_t> outcomes_;
  std::size_t requeued_ = 0;
  double wall_sum_s_ = 0;
  std::size_t wall_n_ = 0;
};

// "1h02m", "3m05s", "42s".
std::string FormatDuration(double seconds);

}  // namespace swarmbox::experiment
