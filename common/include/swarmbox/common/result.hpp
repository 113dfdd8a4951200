// Result<T>: the return type for expected failures (HTTP, ssh, YAML, DDS, files).
//
// The middle of the three error tiers (STYLE.md 9): broken invariants abort (SWARMBOX_CHECK),
// expected failures are returned as Result<T>, exceptions only for bad start-up configuration.
// An Error carries a small code that says whether retrying makes sense, a message for humans and
// `where` (the endpoint, file:line:col, DDS call...) recorded once at the boundary that converted
// the foreign error (STYLE.md 10).
//
//   Result<Image> img = docker.BuildImage(ctx);
//   if (!img) return img.error().Context("building image physics");
//   Use(*img);
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

namespace swarmbox {

enum class ErrorCode {
  kInvalidArgument,   // the caller's input is wrong: retrying the same call cannot help
  kNotFound,          // the thing asked for does not exist
  kAlreadyExists,     // creating something that is already there
  kUnavailable,       // the peer/service is not there now (engine down, host unreachable): retry may help
  kTimeout,           // gave up waiting: retry may help
  kIo,                // file or socket I/O failed
  kProtocol,          // the peer answered something we cannot understand
  kInternal,          // a bug or an unexpected state in a dependency
  kCancelled,         // the operation was interrupted (Ctrl-C, shutdown)
};

std::string_view ErrorCodeName(ErrorCode code);

// Whether repeating the same operation later may succeed.
constexpr bool IsRetryable(ErrorCode code) {
  return code == ErrorCode::kUnavailable || code == ErrorCode::kTimeout || code == ErrorCode::kIo;
}

class Error {
 public:
  Error(ErrorCode code, std::string message, std::string where = {})
      : code_(code), message_(std::move(message)), where_(std::move(where)) {}

  ErrorCode code() const { return code_; }
  const std::string& message() const { return message_; }
  const std::string& where() const { return where_; }
  bool retryable() const { return IsRetryable(code_); }

  // Prefixes the message with what the caller was doing: "starting physics: <message>".
  Error Context(std::string_view doing) const& {
    return Error(code_, std::string(doing) + ": " + message_, where_);
  }
  Error Context(std::string_view doing) && {
    message_ = std::string(doing) + ": " + message_;
    return std::move(*this);
  }

  // "where: message" (or just the message), for logs and terminals.
  std::string ToString() const { return where_.empty() ? message_ : where_ + ": " + message_; }

 private:
  ErrorCode code_;
  std::string message_;
  std::string where_;
};

// Marker for a successful Result<void>.
struct Ok {};

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}  // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & { return Check(), std::get<0>(v_); }
  const T& value() const& { return Check(), std::get<0>(v_); }
  T&& value() && { return Check(), std::get<0>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T&& operator*() && { return std::move(*this).value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

  const Error& error() const& {
    if (ok()) Die("Result::error() called on a value");
    return std::get<1>(v_);
  }
  Error&& error() && {
    if (ok()) Die("Result::error() called on a value");
    return std::get<1>(std::move(v_));
  }

  template <typename U>
  T value_or(U&& fallback) const& {
    return ok() ? std::get<0>(v_) : static_cast<T>(std::forward<U>(fallback));
  }

 private:
  void Check() const {
    if (!ok()) Die(std::get<1>(v_).ToString().c_str());
  }
  [[noreturn]] static void Die(const char* what) {
    std::fprintf(stderr, "swarmbox: fatal: value() on an error Result: %s\n", what);
    std::abort();
  }
  std::variant<T, Error> v_;
};

template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Ok) {}  // NOLINT(google-explicit-constructor)
  Result(Error error) : error_(std::move(error)), has_error_(true) {}  // NOLINT

  bool ok() const { return !has_error_; }
  explicit operator bool() const { return ok(); }
  const Error& error() const {
    if (ok()) {
      std::fprintf(stderr, "swarmbox: fatal: Result<void>::error() called on success\n");
      std::abort();
    }
    return error_;
  }

 private:
  Error error_{ErrorCode::kInternal, ""};
  bool has_error_ = false;
};

using Status = Result<void>;

}  // namespace swarmbox

// Always-on check for broken invariants (the first error tier): prints where and aborts.
#define SWARMBOX_CHECK(cond)                                                                    \
  do {                                                                                          \
    if (!(cond)) {                                                                              \
      std::fprintf(stderr, "swarmbox: check failed at %s:%d: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                             \
    }                                                                                           \
  } while (false)

// Early return for Result-returning code: SWARMBOX_TRY(status_or_result_expr);
#define SWARMBOX_TRY(expr)                           \
  do {                                               \
    auto&& swarmbox_try_r_ = (expr);                 \
    if (!swarmbox_try_r_) return swarmbox_try_r_.error(); \
  } while (false)
