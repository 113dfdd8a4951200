// DockerEngine's two background pipelines, each owning its state under its own lock (private to
// DockerEngine; the header is here so the engine's header can hold them by value).
//
// CreatesAhead: the containers whose creation was queued (CreateContainer with max_parallel > 1):
// each one's verdict once created, the build traces left to the creation, and the creations not
// finished per run priority, so a level's creation waits for the earlier levels' to finish.
//
// BackgroundStops: the second half of each container's stop (Docker's stop call, exit code,
// artifacts, removal) on a thread of its own; Join waits for them all and keeps the worst verdict.
#pragma once

#include <condition_variable>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "swarmbox/dsl/outcome.hpp"

namespace swarmbox::runner::detail {

class CreatesAhead {
 public:
  // Registers the component's creation at run priority `priority`; its verdict is the future of
  // the returned promise, which Finished() fulfils.
  std::shared_ptr<std::promise<dsl::Verdict>> Add(const std::string& component, int priority);
  // The component's queued creation, if any (the future of a creation not finished yet too).
  std::optional<std::shared_future<dsl::Verdict>> Find(const std::string& component) const;
  // Blocks until every creation of a lower run priority has finished.
  void WaitForEarlierLevels(int priority);
  // The creation at `priority` finished with `verdict`.
  void Finished(int priority, const std::shared_ptr<std::promise<dsl::Verdict>>& promise,
                const dsl::Verdict& verdict);
  // True once for a component whose build trace its creation writes (the tree's is dropped).
  bool TakeBuildTrace(const std::string& component);
  // Forgets the component's creation (its container is stopped; a rebuild may create it again).
  void Forget(const std::string& component);
  // Every creation queued and not forgotten.
  std::vector<std::shared_future<dsl::Verdict>> All() const;

 private:
  mutable std::mutex mu_;
  std::condition_variable finished_cv_;
  std::map<std::string, std::shared_future<dsl::Verdict>> creates_;  // guarded by mu_
  std::set<std::string> build_traced_by_create_;                    // guarded by mu_
  std::map<int, int> unfinished_;  // run priority -> creations not finished; guarded by mu_
};

class BackgroundStops {
 public:
  struct Pending {
    std::thread thread;
    dsl::Verdict verdict;  // written by `thread`, read after joining it
  };
  ~BackgroundStops();  // Join()
  // Runs `finish` on a thread of its own at once. Join() waits for it once it is handed to Keep()
  // (DockerEngine does once the container's log is complete, as a stop before returning).
  static std::unique_ptr<Pending> Launch(std::function<dsl::Verdict()> finish);
  void Keep(std::unique_ptr<Pending> pending);
  // Waits for every stop kept so far (one joiner at a time: a second caller returns once the
  // first has joined everything) and keeps their worst verdict.
  void Join();
  // Join(), then the worst verdict since the last Take().
  dsl::Verdict Take();

 private:
  std::mutex mu_;
  std::vector<std::unique_ptr<Pending>> pending_;  // guarded by mu_
  dsl::Verdict verdict_;                           // guarded by mu_
  std::mutex join_mu_;                             // held while Join joins
};

}  // namespace swarmbox::runner::detail
