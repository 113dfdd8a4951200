// LogTee: a stdio stream that passes every byte on to another stream, unchanged, and also hands
// each complete line to a callback. For programs whose log lines are written by several parts
// through one FILE* (the agent's logfmt events: the node, the Raft host, the brain host), so a
// copy of every line can be queued elsewhere (the agent's telemetry for the recording) without
// touching any of the writers.
//
//   auto tee = LogTee::Create(stdout, [&](std::string_view line) { queue.push_back(...); });
//   std::fprintf(tee->file(), "t=1.000 node=a event=x\n");  // on stdout, and to the callback
//
// The tee stream is line-buffered and flushes `out` after each line (what the writers did with
// fflush). The callback runs inside the writer's fprintf/fflush, under the stream's lock (so one
// call at a time); it must not write to the tee stream. A line without its '\n' at destruction is
// passed on and handed over as it is. Linux (glibc's fopencookie).
#pragma once

#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"

namespace swarmbox {

class LogTee {
 public:
  using LineFn = std::function<void(std::string_view line)>;  // without the '\n'

  // kInternal when the C library cannot make the stream. `out` must outlive the tee.
  static Result<std::unique_ptr<LogTee>> Create(std::FILE* out, LineFn on_line);
  ~LogTee();  // flushes and closes the tee stream (not `out`)
  LogTee(const LogTee&) = delete;
  LogTee& operator=(const LogTee&) = delete;

  std::FILE* file() const { return file_; }

 private:
  LogTee(std::FILE* out, LineFn on_line) : out_(out), on_line_(std::move(on_line)) {}
  static long Write(void* cookie, const char* data, std::size_t size);  // fopencookie's write
  void Take(std::string_view data);
  void Finish();

  std::FILE* out_;
  LineFn on_line_;
  std::string pending_;  // bytes after the last '\n'
  std::FILE* file_ = nullptr;
};

}  // namespace swarmbox
