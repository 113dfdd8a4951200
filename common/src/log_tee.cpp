#include "swarmbox/common/log_tee.hpp"

#include <cerrno>
#include <cstring>

namespace swarmbox {

Result<std::unique_ptr<LogTee>> LogTee::Create(std::FILE* out, LineFn on_line) {
  std::unique_ptr<LogTee> tee(new LogTee(out, std::move(on_line)));
  cookie_io_functions_t io{};
  io.write = [](void* cookie, const char* data, std::size_t size) -> ssize_t {
    return static_cast<ssize_t>(Write(cookie, data, size));
  };
  tee->file_ = fopencookie(tee.get(), "w", io);
  if (tee->file_ == nullptr) {
    return Error(ErrorCode::kInternal, std::string("fopencookie: ") + std::strerror(errno));
  }
  if (std::setvbuf(tee->file_, nullptr, _IOLBF, 4096) != 0) {
    return Error(ErrorCode::kInternal, "setvbuf on the log tee failed");
  }
  return tee;
}

LogTee::~LogTee() {
  if (file_ != nullptr) std::fclose(file_);  // flushes through Write
  Finish();
}

long LogTee::Write(void* cookie, const char* data, std::size_t size) {
  static_cast<LogTee*>(cookie)->Take(std::string_view(data, size));
  return static_cast<long>(size);
}

void LogTee::Take(std::string_view data) {
  std::size_t start = 0;
  while (start < data.size()) {
    const std::size_t nl = data.find('\n', start);
    if (nl == std::string_view::npos) {
      pending_.append(data.substr(start));
      return;
    }
    const std::string_view piece = data.substr(start, nl - start);
    std::string_view line = piece;
    if (!pending_.empty()) {
      pending_.append(piece);
      line = pending_;
    }
    std::fwrite(line.data(), 1, line.size(), out_);
    std::fputc('\n', out_);
    std::fflush(out_);
    if (on_line_) on_line_(line);
    pending_.clear();
    start = nl + 1;
  }
}

void LogTee::Finish() {
  if (pending_.empty()) return;
  std::fwrite(pending_.data(), 1, pending_.size(), out_);
  std::fflush(out_);
  if (on_line_) on_line_(pending_);
  pending_.clear();
}

}  // namespace swarmbox
