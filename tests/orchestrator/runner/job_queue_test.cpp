// JobQueue: jobs run on at most max_threads workers, in the order posted; Close cancels what is
// still queued and runs late jobs on the caller. Built with ThreadSanitizer in the tsan stage.
#include "swarmbox/runner/job_queue.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

namespace swarmbox::runner {
namespace {

TEST(JobQueue, RunsEveryJobOnNoMoreThreadsThanItsLimit) {
  std::atomic<int> running{0};
  std::atomic<int> most{0};
  std::atomic<int> done{0};
  {
    JobQueue queue(3);
    for (int i = 0; i < 20; ++i) {
      queue.Post([&](bool) {
        const int now = running.fetch_add(1) + 1;
        int seen = most.load();
        while (now > seen && !most.compare_exchange_weak(seen, now)) {
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        running.fetch_sub(1);
        done.fetch_add(1);
      });
    }
    EXPECT_LE(queue.threads(), 3);
    EXPECT_GE(queue.threads(), 1);
  }  // the destructor closes the queue: what was still queued runs too (cancelled)
  EXPECT_EQ(done.load(), 20);
  EXPECT_LE(most.load(), 3);
}

TEST(JobQueue, TakesJobsInTheOrderTheyWerePosted) {
  std::mutex mu;
  std::vector<int> order;
  {
    JobQueue queue(1);
    for (int i = 0; i < 10; ++i) {
      queue.Post([&, i](bool) {
        std::lock_guard lock(mu);
        order.push_back(i);
      });
    }
  }
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
}

TEST(JobQueue, AJobWaitingForAnEarlierOneIsNotStarved) {
  // Two workers, the second job waits for the first: the first was taken before it, so it runs.
  std::promise<int> first;
  std::shared_future<int> first_done = first.get_future().share();
  std::promise<int> second;
  JobQueue queue(2);
  queue.Post([&](bool) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    first.set_value(1);
  });
  queue.Post([&](bool) { second.set_value(first_done.get() + 1); });
  auto result = second.get_future();
  ASSERT_EQ(result.wait_for(std::chrono::seconds(10)), std::future_status::ready);
  EXPECT_EQ(result.get(), 2);
}

TEST(JobQueue, CloseCancelsQueuedJobsAndRunsLateOnesOnTheCaller) {
  JobQueue queue(1);
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::promise<void> started;
  std::atomic<bool> first_cancelled{true};
  queue.Post([&](bool c) {  // holds the only worker until released
    first_cancelled.store(c);
    started.set_value();
    released.wait();
  });
  started.get_future().wait();  // taken before Close: not cancelled
  std::mutex mu;
  std::vector<bool> queued_cancelled;
  for (int i = 0; i < 2; ++i) {
    queue.Post([&](bool c) {
      std::lock_guard lock(mu);
      queued_cancelled.push_back(c);
    });
  }
  std::thread closer([&] { queue.Close(); });
  // Once Close has begun, a job posted runs at once on the posting thread, cancelled. Jobs posted
  // before that wait behind the first one (and run cancelled once it is released).
  const std::thread::id me = std::this_thread::get_id();
  bool ran_here = false;
  for (int i = 0; i < 10000 && !ran_here; ++i) {
    queue.Post([&](bool c) {
      if (std::this_thread::get_id() == me) {
        EXPECT_TRUE(c);
        ran_here = true;
      }
    });
    if (!ran_here) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  release.set_value();
  closer.join();
  EXPECT_TRUE(ran_here);
  EXPECT_FALSE(first_cancelled.load());
  EXPECT_EQ(queued_cancelled, (std::vector<bool>{true, true}));
  EXPECT_EQ(queue.threads(), 0);
}

}  // namespace
}  // namespace swarmbox::runner
