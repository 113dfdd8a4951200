// CancelToken: stops a long-running Docker call (log follow, events, wait, build) from another
// thread, promptly.
//
//   docker::CancelToken cancel;
//   std::thread t([&] { api.FollowLogs(id, {}, on_line, &cancel); });
//   ...
//   cancel.Cancel();   // FollowLogs returns ErrorCode::kCancelled within milliseconds
//   t.join();
//
// Thread-safety: every member is safe to call from any thread, also from inside a callback of the
// call being cancelled. A token is one-shot: once cancelled it stays cancelled; use a new token for
// the next call. A token may be shared by several concurrent calls (cancelling stops all of them).
// The token must outlive every call it was passed to.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>

namespace swarmbox::docker {

class CancelToken {
 public:
  CancelToken() = default;
  CancelToken(const CancelToken&) = delete;
  CancelToken& operator=(const CancelToken&) = delete;

  // Requests cancellation and runs every registered waker once (outside no lock of the caller).
  void Cancel();
  bool cancelled() const { return cancelled_.load(std::memory_order_acquire); }

  // For transports: `wake` is called once when Cancel() happens while registered (or immediately
  // when the token is already cancelled). Returns an id for Unregister(). `wake` must be cheap and
  // must not call back into the token.
  std::uint64_t Register(std::function<void()> wake);
  // After Unregister() returns, the waker is not running and will not run again.
  void Unregister(std::uint64_t id);

 private:
  std::atomic<bool> cancelled_{false};
  std::mutex mu_;
  std::uint64_t next_id_ = 1;
  std::map<std::uint64_t, std::function<void()>> wakers_;
};

}  // namespace swarmbox::docker
