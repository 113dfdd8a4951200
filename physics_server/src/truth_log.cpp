#include "swarmbox/physics/truth_log.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <utility>

namespace swarmbox::physics {
namespace {

void AppendF(std::string* out, const char* fmt, double v) {
  char buf[48];
  const int n = std::snprintf(buf, sizeof buf, fmt, v);
  const char* p = buf;
  if (buf[0] == '-' && std::strspn(buf + 1, "0.") == static_cast<std::size_t>(n - 1)) ++p;  // "-0.000" -> "0.000"
  out->append(p, static_cast<std::size_t>(n) - static_cast<std::size_t>(p - buf));
}

}  // namespace

std::string TruthCsvHeader() {
  std::string h = "t_s,drone,x_m,y_m,z_m,vx_m_s,vy_m_s,vz_m_s,qw,qx,qy,qz,p_rad_s,q_rad_s,r_rad_s";
  for (int i = 0; i < 8; ++i) h += ",w" + std::to_string(i) + "_rad_s";
  h += ",payload_attached,payload_swing_rad,crashed,lost\n";
  return h;
}

std::string TruthCsvRow(double t_s, const std::string& drone, const DroneTruth& t) {
  std::string row;
  row.reserve(320);
  AppendF(&row, "%.3f", t_s);
  row += ',';
  row += drone;
  for (double v : {t.position_m.x, t.position_m.y, t.position_m.z, t.velocity_m_s.x, t.velocity_m_s.y,
                   t.velocity_m_s.z}) {
    row += ',';
    AppendF(&row, "%.4f", v);
  }
  for (double v : {t.attitude.w, t.attitude.x, t.attitude.y, t.attitude.z, t.body_rates_rad_s.x,
                   t.body_rates_rad_s.y, t.body_rates_rad_s.z}) {
    row += ',';
    AppendF(&row, "%.5f", v);
  }
  for (int i = 0; i < 8; ++i) {
    row += ',';
    if (i < t.rotor_count) AppendF(&row, "%.2f", t.rotor_speed_rad_s[i]);
  }
  row += t.payload_attached ? ",1," : ",0,";
  AppendF(&row, "%.4f", t.payload_swing_rad);
  row += t.crashed ? ",1" : ",0";
  row += t.lost ? ",1\n" : ",0\n";
  return row;
}

TruthCsvFile::TruthCsvFile(std::FILE* file, std::int64_t period_ns) : file_(file), period_ns_(period_ns) {}

TruthCsvFile::TruthCsvFile(TruthCsvFile&& other) noexcept
    : file_(std::exchange(other.file_, nullptr)), period_ns_(other.period_ns_), next_ns_(other.next_ns_) {}

TruthCsvFile::~TruthCsvFile() {
  if (file_ != nullptr) std::fclose(file_);
}

Result<TruthCsvFile> TruthCsvFile::Open(const std::string& path, double rate_hz) {
  if (!(rate_hz > 0) || !std::isfinite(rate_hz)) {
    return Error(ErrorCode::kInvalidArgument, "truth rate must be > 0 Hz", path);
  }
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return Error(ErrorCode::kIo, std::string("cannot open for writing: ") + std::strerror(errno), path);
  const std::string header = TruthCsvHeader();
  if (std::fwrite(header.data(), 1, header.size(), f) != header.size()) {
    std::fclose(f);
    return Error(ErrorCode::kIo, "write failed", path);
  }
  return TruthCsvFile(f, static_cast<std::int64_t>(std::llround(1e9 / rate_hz)));
}

Status TruthCsvFile::MaybeWrite(const World& world) {
  if (file_ == nullptr) return Error(ErrorCode::kInternal, "truth file is closed");
  if (world.time_ns() < next_ns_) return Ok{};
  while (next_ns_ <= world.time_ns()) next_ns_ += period_ns_;
  for (std::size_t i = 0; i < world.drone_count(); ++i) {
    const std::string row = TruthCsvRow(world.time_s(), world.drone_name(i), world.Truth(i));
    if (std::fwrite(row.data(), 1, row.size(), file_) != row.size()) {
      return Error(ErrorCode::kIo, std::string("truth.csv write failed: ") + std::strerror(errno));
    }
  }
  return Ok{};
}

Status TruthCsvFile::Flush() {
  if (file_ != nullptr && std::fflush(file_) != 0) {
    return Error(ErrorCode::kIo, std::string("truth.csv flush failed: ") + std::strerror(errno));
  }
  return Ok{};
}

}  // namespace swarmbox::physics
