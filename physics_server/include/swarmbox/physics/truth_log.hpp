// truth.csv: every drone's ground truth over time (ARCHITECTURE.md "Per-trial output").
//
// Columns: t_s,drone,x_m,y_m,z_m,vx_m_s,vy_m_s,vz_m_s,qw,qx,qy,qz,p_rad_s,q_rad_s,r_rad_s,
//          w0_rad_s..w7_rad_s (empty past the drone's rotor count),payload_attached,
//          payload_swing_rad,crashed,lost
// One row per drone per sample, fixed decimals, so the same run gives a byte-identical file.
#pragma once

#include <cstdio>
#include <string>

#include "swarmbox/common/result.hpp"
#include "swarmbox/physics/world.hpp"

namespace swarmbox::physics {

// Formats rows (pure); TruthCsvFile writes them.
std::string TruthCsvHeader();
std::string TruthCsvRow(double t_s, const std::string& drone, const DroneTruth& truth);

class TruthCsvFile {
 public:
  // rate_hz: samples per simulated second (the World is sampled when a period has passed).
  static Result<TruthCsvFile> Open(const std::string& path, double rate_hz);
  TruthCsvFile(TruthCsvFile&& other) noexcept;
  TruthCsvFile& operator=(TruthCsvFile&&) = delete;
  TruthCsvFile(const TruthCsvFile&) = delete;
  ~TruthCsvFile();

  // Writes every drone's row if a sample is due at world.time_ns(). Returns I/O errors.
  Status MaybeWrite(const World& world);
  Status Flush();

 private:
  TruthCsvFile(std::FILE* file, std::int64_t period_ns);
  std::FILE* file_ = nullptr;
  std::int64_t period_ns_ = 0;
  std::int64_t next_ns_ = 0;
};

}  // namespace swarmbox::physics
