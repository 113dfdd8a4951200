#include "swarmbox/channel/radio_profile.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>

namespace swarmbox::channel {
namespace {

using yaml::MapReader;
using yaml::Node;

// Where `key` of `map` is written (the map's own mark when absent).
std::string WhereOf(const Node& map, std::string_view key) {
  const Node* n = map.Find(key);
  return n != nullptr ? n->Where() : map.Where();
}

Error Invalid(std::string message, std::string where = {}) {
  return Error(ErrorCode::kInvalidArgument, std::move(message), std::move(where));
}

// The value checks, each naming its key; `where(key)` says where the key was written.
template <typename WhereFn>
Status Validate(const RadioProfile& p, WhereFn where) {
  struct Rule {
    const char* key;
    double value;
    bool ok;
    const char* need;
  };
  const PathLossModel& pl = p.path_loss;
  const Rule rules[] = {
      {"frequency_mhz", p.frequency_mhz, p.frequency_mhz > 0, "must be positive"},
      {"tx_power_dbm", p.tx_power_dbm, std::isfinite(p.tx_power_dbm), "must be a finite number"},
      {"antenna_gain_dbi", p.antenna_gain_dbi, std::isfinite(p.antenna_gain_dbi), "must be a finite number"},
      {"noise_floor_dbm", p.noise_floor_dbm, std::isfinite(p.noise_floor_dbm), "must be a finite number"},
      {"path_loss.exponent", pl.exponent, pl.exponent > 0 && pl.exponent <= 8, "must be in (0, 8]"},
      {"path_loss.reference_loss_db", pl.reference_loss_db, std::isfinite(pl.reference_loss_db),
       "must be a finite number"},
      {"path_loss.reference_distance_m", pl.reference_distance_m, pl.reference_distance_m > 0, "must be positive"},
      {"path_loss.shadowing_sigma_db", pl.shadowing_sigma_db, pl.shadowing_sigma_db >= 0 && pl.shadowing_sigma_db <= 30,
       "must be in [0, 30]"},
      {"path_loss.decorrelation_m", pl.decorrelation_m, pl.decorrelation_m > 0, "must be positive"},
      {"obstacle_loss_db", p.obstacle_loss_db, p.obstacle_loss_db >= 0, "must be at least 0"},
      {"per.snr50_db", p.per.snr50_db, std::isfinite(p.per.snr50_db), "must be a finite number"},
      {"per.width_db", p.per.width_db, p.per.width_db > 0, "must be positive"},
      {"max_range_m", p.max_range_m, p.max_range_m > 0, "must be positive"},
      {"data_rate_bps", p.data_rate_bps, p.data_rate_bps > 0, "must be positive"},
      {"capacity_bps", p.capacity_bps, p.capacity_bps > 0, "must be positive"},
      {"frame_overhead_us", p.frame_overhead_us, p.frame_overhead_us >= 0, "must be at least 0"},
      {"queue_frames", static_cast<double>(p.queue_frames), p.queue_frames >= 1 && p.queue_frames <= 100000,
       "must be in [1, 100000]"},
      {"access_wait_max_us", p.access_wait_max_us, p.access_wait_max_us >= 0, "must be at least 0"},
  };
  for (const Rule& r : rules) {
    if (!r.ok || std::isnan(r.value)) {
      return Invalid(std::string("radio profile ") + r.key + " " + r.need, where(r.key));
    }
  }
  return Ok{};
}

template <typename Fn>
void Nested(MapReader& parent, std::string_view key, std::string what, Fn fn) {
  const Node* child = parent.Child(key, /*required=*/true);
  if (child == nullptr) return;
  MapReader r(*child, std::move(what));
  fn(r);
  if (auto s = r.Finish(); !s) parent.Fail(s.error());
}

}  // namespace

Status ValidateRadioProfile(const RadioProfile& profile) {
  return Validate(profile, [&](std::string_view) { return profile.source; });
}

Result<RadioProfile> ParseRadioProfile(const Node& root, std::string source) {
  if (!root.is_mapping()) return Invalid("a radio profile must be a mapping", root.Where());
  RadioProfile p;
  p.source = std::move(source);
  MapReader r(root, "radio profile");
  r.Required("name", &p.name)
      .Required("frequency_mhz", &p.frequency_mhz)
      .Required("tx_power_dbm", &p.tx_power_dbm)
      .Required("antenna_gain_dbi", &p.antenna_gain_dbi)
      .Required("noise_floor_dbm", &p.noise_floor_dbm);
  Nested(r, "path_loss", "path_loss", [&](MapReader& s) {
    s.Required("exponent", &p.path_loss.exponent)
        .Required("reference_loss_db", &p.path_loss.reference_loss_db)
        .Required("reference_distance_m", &p.path_loss.reference_distance_m)
        .Required("shadowing_sigma_db", &p.path_loss.shadowing_sigma_db)
        .Required("decorrelation_m", &p.path_loss.decorrelation_m);
  });
  r.Required("obstacle_loss_db", &p.obstacle_loss_db);
  Nested(r, "per", "per", [&](MapReader& s) {
    s.Required("snr50_db", &p.per.snr50_db).Required("width_db", &p.per.width_db);
  });
  r.Required("max_range_m", &p.max_range_m)
      .Required("data_rate_bps", &p.data_rate_bps)
      .Required("capacity_bps", &p.capacity_bps)
      .Required("frame_overhead_us", &p.frame_overhead_us)
      .Required("queue_frames", &p.queue_frames)
      .Optional("access_wait_max_us", &p.access_wait_max_us);
  if (auto s = r.Finish(); !s) return s.error();
  if (p.name.empty()) return Invalid("radio profile name must not be empty", WhereOf(root, "name"));
  auto where = [&](std::string_view key) -> std::string {
    const auto dot = key.find('.');
    if (dot == std::string_view::npos) return WhereOf(root, key);
    const Node* parent = root.Find(key.substr(0, dot));
    return parent != nullptr ? WhereOf(*parent, key.substr(dot + 1)) : root.Where();
  };
  if (auto s = Validate(p, where); !s) return s.error();
  return p;
}

Result<RadioProfile> LoadRadioProfile(const std::string& path) {
  auto doc = yaml::ParseFile(path);
  if (!doc) return doc.error();
  return ParseRadioProfile(*doc, path);
}

double MedianPathLossDb(const RadioProfile& p, double distance_m) {
  const PathLossModel& m = p.path_loss;
  const double d = std::max(distance_m, m.reference_distance_m);
  return m.reference_loss_db + 10.0 * m.exponent * std::log10(d / m.reference_distance_m);
}

double SnrDb(const RadioProfile& p, double path_loss_db) {
  return p.tx_power_dbm + 2.0 * p.antenna_gain_dbi - path_loss_db - p.noise_floor_dbm;
}

double PacketErrorRate(const PerCurve& per, double snr_db) {
  const double x = (snr_db - per.snr50_db) / per.width_db;
  if (x > 700) return 0.0;
  if (x < -700) return 1.0;
  return 1.0 / (1.0 + std::exp(x));
}

double RangeForPer(const RadioProfile& p, double per) {
  const double snr = p.per.snr50_db + p.per.width_db * std::log(1.0 / per - 1.0);
  const double path_loss_db = p.tx_power_dbm + 2.0 * p.antenna_gain_dbi - p.noise_floor_dbm - snr;
  const PathLossModel& m = p.path_loss;
  return m.reference_distance_m * std::pow(10.0, (path_loss_db - m.reference_loss_db) / (10.0 * m.exponent));
}

}  // namespace swarmbox::channel
