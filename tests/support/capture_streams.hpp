// CaptureStreams: redirects std::cout and std::cerr into strings while alive (tests of commands
// that print, e.g. the CLI's subcommands called in-process).
//
//   CaptureStreams c;
//   int code = ValidateCommand(args);
//   EXPECT_THAT(c.out(), HasSubstr("ok"));
#pragma once

#include <iostream>
#include <sstream>
#include <string>

namespace swarmbox::testing {

class CaptureStreams {
 public:
  CaptureStreams() : out_old_(std::cout.rdbuf(out_.rdbuf())), err_old_(std::cerr.rdbuf(err_.rdbuf())) {}
  ~CaptureStreams() {
    std::cout.rdbuf(out_old_);
    std::cerr.rdbuf(err_old_);
  }
  CaptureStreams(const CaptureStreams&) = delete;
  CaptureStreams& operator=(const CaptureStreams&) = delete;
  std::string out() const { return out_.str(); }
  std::string err() const { return err_.str(); }

 private:
  std::ostringstream out_, err_;
  std::streambuf* out_old_;
  std::streambuf* err_old_;
};

}  // namespace swarmbox::testing
