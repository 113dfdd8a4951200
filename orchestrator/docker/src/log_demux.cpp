#include "swarmbox/docker/log_demux.hpp"

#include <algorithm>
#include <utility>

namespace swarmbox::docker {

LogDemuxer::LogDemuxer(Mode mode, LogLineFn on_line) : mode_(mode), on_line_(std::move(on_line)) {}

void LogDemuxer::Emit(StreamKind stream, std::string& buffer, std::size_t end, std::size_t skip) {
  std::size_t text_end = end;
  if (text_end > 0 && buffer[text_end - 1] == '\r') --text_end;
  LogLine line{stream, buffer.substr(0, text_end)};
  buffer.erase(0, end + skip);
  if (on_line_) on_line_(line);
}

void LogDemuxer::Append(StreamKind stream, std::string_view bytes) {
  std::string& buffer = partial_[static_cast<std::size_t>(stream)];
  while (!bytes.empty()) {
    const std::size_t nl = bytes.find('\n');
    if (nl == std::string_view::npos) {
      buffer.append(bytes);
      while (buffer.size() >= kMaxLineBytes) Emit(stream, buffer, kMaxLineBytes, 0);
      return;
    }
    buffer.append(bytes.substr(0, nl));
    bytes.remove_prefix(nl + 1);
    while (buffer.size() > kMaxLineBytes) Emit(stream, buffer, kMaxLineBytes, 0);
    Emit(stream, buffer, buffer.size(), 0);
  }
}

Status LogDemuxer::Feed(std::string_view bytes) {
  if (mode_ == Mode::kRaw) {
    Append(StreamKind::kStdout, bytes);
    return Ok{};
  }
  while (!bytes.empty()) {
    if (payload_left_ > 0) {
      const std::size_t n = std::min(payload_left_, bytes.size());
      Append(payload_stream_, bytes.substr(0, n));
      bytes.remove_prefix(n);
      payload_left_ -= n;
      continue;
    }
    const std::size_t need = header_.size() - header_have_;
    const std::size_t n = std::min(need, bytes.size());
    for (std::size_t i = 0; i < n; ++i) {
      header_[header_have_ + i] = static_cast<unsigned char>(bytes[i]);
    }
    header_have_ += n;
    bytes.remove_prefix(n);
    if (header_have_ < header_.size()) break;
    header_have_ = 0;
    const unsigned char kind = header_[0];
    if (kind > 2 || header_[1] != 0 || header_[2] != 0 || header_[3] != 0) {
      // Not a frame header: hand everything (these 8 bytes included) over as raw stdout.
      mode_ = Mode::kRaw;
      std::string head(reinterpret_cast<const char*>(header_.data()), header_.size());
      Append(StreamKind::kStdout, head);
      Append(StreamKind::kStdout, bytes);
      return Error(ErrorCode::kProtocol,
                   "log stream is not multiplexed (frame header byte " + std::to_string(kind) +
                       "); reading it as raw output");
    }
    payload_stream_ = static_cast<StreamKind>(kind);
    payload_left_ = (static_cast<std::size_t>(header_[4]) << 24) |
                    (static_cast<std::size_t>(header_[5]) << 16) |
                    (static_cast<std::size_t>(header_[6]) << 8) | static_cast<std::size_t>(header_[7]);
  }
  return Ok{};
}

Status LogDemuxer::Finish() {
  const bool truncated = payload_left_ > 0 || header_have_ > 0;
  const std::size_t missing = payload_left_;
  payload_left_ = 0;
  header_have_ = 0;
  for (std::size_t i = 0; i < partial_.size(); ++i) {
    if (!partial_[i].empty()) Emit(static_cast<StreamKind>(i), partial_[i], partial_[i].size(), 0);
  }
  if (truncated) {
    return Error(ErrorCode::kProtocol, "log stream ended inside a frame (" +
                                           std::to_string(missing) + " payload bytes missing)");
  }
  return Ok{};
}

}  // namespace swarmbox::docker
