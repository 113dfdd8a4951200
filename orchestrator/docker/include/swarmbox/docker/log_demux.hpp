// Decoding Docker's log and attach streams into lines (pure: bytes in, lines out; no I/O).
//
// A container without a TTY sends stdout and stderr multiplexed in frames:
//   [stream:1][0 0 0][size:4, big-endian][payload:size]       stream 0 stdin, 1 stdout, 2 stderr
// A container with a TTY sends raw bytes (all stdout). Either way bytes arrive in arbitrary chunks
// (a frame header or a line may be split across chunks, a frame may hold many lines or part of
// one); these classes reassemble complete lines per stream and hand each over as soon as its '\n'
// arrives. "\r\n" endings lose the '\r' too.
//
//   LogDemuxer demux(LogDemuxer::Mode::kMultiplexed, on_line);
//   transport.Send(req, [&](std::string_view chunk) { demux.Feed(chunk); }, &cancel);
//   demux.Finish();   // delivers a last unterminated line per stream
//
// Not thread-safe: one demuxer per stream. Lines longer than kMaxLineBytes are delivered in
// pieces of that size (a runaway writer cannot make us buffer without bound).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"

namespace swarmbox::docker {

class LogDemuxer {
 public:
  enum class Mode { kMultiplexed, kRaw };
  static constexpr std::size_t kMaxLineBytes = 1 << 20;

  LogDemuxer(Mode mode, LogLineFn on_line);

  // Consumes the next bytes of the stream. A frame header with an unknown stream byte or non-zero
  // padding is a protocol error (the stream is probably raw, not multiplexed): it is returned as
  // kProtocol once, and the demuxer then treats the rest as raw stdout so nothing is lost.
  Status Feed(std::string_view bytes);
  // End of stream: delivers each stream's unterminated tail as a last line. Returns kProtocol when
  // the stream stopped inside a frame (a truncated frame's bytes are still delivered).
  Status Finish();

  Mode mode() const { return mode_; }

 private:
  void Append(StreamKind stream, std::string_view bytes);
  void Emit(StreamKind stream, std::string& buffer, std::size_t end, std::size_t skip);

  Mode mode_;
  LogLineFn on_line_;
  std::array<unsigned char, 8> header_{};
  std::size_t header_have_ = 0;
  std::size_t payload_left_ = 0;
  StreamKind payload_stream_ = StreamKind::kStdout;
  std::array<std::string, 3> partial_;  // per stream kind
};

// Splits a byte stream into '\n'-terminated lines (build output and events arrive as
// newline-delimited JSON). Not thread-safe.
class LineSplitter {
 public:
  // Calls `on_line` for every complete line in the bytes seen so far (without "\n" / "\r\n").
  template <typename Fn>
  void Feed(std::string_view bytes, Fn&& on_line) {
    buffer_.append(bytes);
    std::size_t start = 0;
    for (std::size_t nl = buffer_.find('\n'); nl != std::string::npos;
         nl = buffer_.find('\n', start)) {
      std::size_t end = nl;
      if (end > start && buffer_[end - 1] == '\r') --end;
      on_line(std::string_view(buffer_).substr(start, end - start));
      start = nl + 1;
    }
    buffer_.erase(0, start);
  }
  // The unterminated rest (possibly empty); clears it.
  std::string TakeRest() {
    std::string rest;
    rest.swap(buffer_);
    return rest;
  }

 private:
  std::string buffer_;
};

}  // namespace swarmbox::docker
