// RadioProfile: the figures of one radio (a 5 GHz 802.11s mesh card, a 900 MHz telemetry modem),
// read from trials/radios/<name>.yaml, and the link-budget arithmetic on them.
//
// Every figure in a shipped profile carries its source in a comment (shared REFERENCES.md keys).
// The schema (all keys required unless marked optional):
//
//   name: wifi_5ghz_mesh
//   frequency_mhz: 5180
//   tx_power_dbm: 15
//   antenna_gain_dbi: 0            # each side
//   noise_floor_dbm: -91
//   path_loss: {exponent: 2.2, reference_loss_db: 46.7, reference_distance_m: 1,
//               shadowing_sigma_db: 3, decorrelation_m: 20}
//   obstacle_loss_db: 20           # per obstacle box crossing the line of sight
//   per: {snr50_db: 0.1, width_db: 0.45}
//   max_range_m: 760               # nothing arrives beyond; follows from the budget (RangeForPer)
//   data_rate_bps: 6500000         # PHY rate: airtime = size*8/data_rate + frame_overhead
//   capacity_bps: 6500000          # the shared medium holds a frame max(airtime, size*8/capacity)
//   frame_overhead_us: 120         # preamble, DIFS, mean backoff
//   queue_frames: 64               # per sender
//   access_wait_max_us: 0          # optional: a uniform wait for the sender's slot (TDM radios)
//
//   Result<RadioProfile> p = LoadRadioProfile("trials/radios/wifi_5ghz_mesh.yaml");
//   if (!p) return p.error();     // "wifi_5ghz_mesh.yaml:7:12: ..." (file:line:col)
#pragma once

#include <cstdint>
#include <string>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::channel {

// Log-distance path loss with log-normal shadowing (REFERENCES 1.3):
//   PL(d) = reference_loss_db + 10 * exponent * log10(d / reference_distance_m) + X,
//   X ~ N(0, shadowing_sigma_db), one draw per unordered drone pair and pair of position cells
//   (cubes of decorrelation_m), so X is constant while both drones stay in their cells.
struct PathLossModel {
  double exponent = 2.0;
  double reference_loss_db = 40.0;
  double reference_distance_m = 1.0;
  double shadowing_sigma_db = 0.0;
  double decorrelation_m = 20.0;
};

// PER = 1 / (1 + exp((SNR - snr50_db) / width_db)) (REFERENCES 1.4).
struct PerCurve {
  double snr50_db = 0.0;
  double width_db = 0.5;
};

struct RadioProfile {
  std::string name;
  std::string source;             // the file it came from ("" when built in code)
  double frequency_mhz = 0;
  double tx_power_dbm = 0;
  double antenna_gain_dbi = 0;    // each side
  double noise_floor_dbm = -90;
  PathLossModel path_loss;
  double obstacle_loss_db = 0;    // per obstacle crossing the line of sight
  PerCurve per;
  double max_range_m = 0;         // nothing arrives beyond
  double data_rate_bps = 1e6;
  double capacity_bps = 1e6;      // the shared medium
  double frame_overhead_us = 0;   // preamble, DIFS, mean backoff: added to every frame's airtime
  std::uint32_t queue_frames = 64;  // per sender
  double access_wait_max_us = 0;  // a uniform wait in [0, max] before the frame joins the medium
};

Result<RadioProfile> ParseRadioProfile(const yaml::Node& root, std::string source = {});
Result<RadioProfile> LoadRadioProfile(const std::string& path);
// The checks ParseRadioProfile makes on the values (positive rates, sigma >= 0 ...), for profiles
// built in code. Errors name the key.
Status ValidateRadioProfile(const RadioProfile& profile);

// --- link budget (pure arithmetic on a profile) ---------------------------------------------------
// Median path loss at distance d (no shadowing) [dB]; d below reference_distance_m is clamped.
double MedianPathLossDb(const RadioProfile& p, double distance_m);
// SNR [dB] for a path loss [dB]: tx_power + 2 * antenna_gain - path_loss - noise_floor.
double SnrDb(const RadioProfile& p, double path_loss_db);
// The sigmoid PER for an SNR [dB], in [0, 1].
double PacketErrorRate(const PerCurve& per, double snr_db);
// The distance [m] at which the median SNR gives packet error rate `per` (0 < per < 1). The
// shipped profiles state max_range_m = RangeForPer(p, kMaxRangePer).
double RangeForPer(const RadioProfile& p, double per);
inline constexpr double kMaxRangePer = 0.9999;

}  // namespace swarmbox::channel
