// JobQueue: a small generic work queue. Runs queued jobs on up to `max_threads` worker threads: a
// worker is started when a job is posted and none is idle (up to the limit); workers then live
// until Close(). Jobs are taken in the order they were posted, so a job that waits for an earlier
// one cannot starve the queue (the earlier one is running or done). (Not experiment::WorkQueue,
// the experiment scheduler's pure state machine of trials and hosts.)
//
// Close() (also the destructor) stops taking new work: jobs still queued then run with
// `cancelled` true (on the workers, which then exit; Close joins them), and a job posted after
// Close runs at once on the posting thread with `cancelled` true. A job must not throw.
//
//   JobQueue queue(4);
//   queue.Post([&](bool cancelled) { if (!cancelled) CreateOne(); else GiveUp(); });
//   queue.Close();   // every job posted has run (or been cancelled) when this returns
//
// Thread-safety: Post and Close may be called from any thread, concurrently; Close from a job
// deadlocks (it joins the job's own worker).
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace swarmbox::runner {

class JobQueue {
 public:
  using Job = std::function<void(bool cancelled)>;

  explicit JobQueue(int max_threads);  // at least one worker
  ~JobQueue();                         // Close()
  JobQueue(const JobQueue&) = delete;
  JobQueue& operator=(const JobQueue&) = delete;

  void Post(Job job);
  void Close();
  // Worker threads started so far (never more than max_threads; 0 after Close).
  int threads() const;

 private:
  void Work();

  const int max_threads_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<Job> jobs_;              // guarded by mu_
  std::vector<std::thread> workers_;  // guarded by mu_
  int idle_ = 0;                      // guarded by mu_
  bool closing_ = false;              // guarded by mu_
};

}  // namespace swarmbox::runner
