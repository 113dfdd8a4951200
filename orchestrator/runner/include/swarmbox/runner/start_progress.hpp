// StartProgress: the terminal lines of a trial's start, counted rather than one per container (a
// 100-drone trial would print 200 lines). Pure: fed the wall time of each creation and start (the
// DockerEngine's build and run traces); no clock or I/O.
//
//   StartProgress p(101);
//   p.OnCreated(0.4);   // "created 1/101"
//   ...                 // at most one line a second in between
//   p.OnStarted(6.2);   // the last: "started 101/101 in 6.2 s"
//
// A count's first and last events always give a line ("in X s" on the last: wall seconds since
// the run began); the others at most once every `every_s`.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

namespace swarmbox::runner {

class StartProgress {
 public:
  explicit StartProgress(std::size_t containers = 0, double every_s = 1.0)
      : total_(containers), every_s_(every_s) {}

  std::optional<std::string> OnCreated(double wall_s) { return Count(created_, "created", wall_s); }
  std::optional<std::string> OnStarted(double wall_s) { return Count(started_, "started", wall_s); }
  // When the last container was created / started (the wall_s given); nullopt before.
  std::optional<double> all_created_s() const { return created_.all_s; }
  std::optional<double> all_started_s() const { return started_.all_s; }
  std::size_t created() const { return created_.n; }
  std::size_t started() const { return started_.n; }
  std::size_t total() const { return total_; }

 private:
  struct Counter {
    std::size_t n = 0;
    double last_line_s = 0;
    std::optional<double> all_s;
  };
  std::optional<std::string> Count(Counter& c, const char* what, double wall_s);

  std::size_t total_;
  double every_s_;
  Counter created_;
  Counter started_;
};

}  // namespace swarmbox::runner
