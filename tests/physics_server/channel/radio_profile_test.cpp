// Radio profiles: the shipped files load, their max range follows from their link budget, the
// 900 MHz profile reproduces the SiK latency it was fitted to, and bad files are reported with
// file:line:col.
#include "swarmbox/channel/radio_profile.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "channel_fixture.hpp"
#include "support/files.hpp"
#include "swarmbox/channel/channel.hpp"

namespace swarmbox::channel {
namespace {

const char* kShipped[] = {"wifi_5ghz_mesh", "telemetry_900mhz"};

TEST(RadioProfile, ShippedProfilesLoadAndTheirRangeFollowsTheLinkBudget) {
  for (const char* name : kShipped) {
    const std::string path = testing::TrialsDir() + "/radios/" + name + ".yaml";
    auto p = LoadRadioProfile(path);
    ASSERT_TRUE(p.ok()) << p.error().ToString();
    EXPECT_EQ(p->name, name);
    EXPECT_EQ(p->source, path);
    const double budget_m = RangeForPer(*p, kMaxRangePer);
    EXPECT_NEAR(p->max_range_m / budget_m, 1.0, 0.01) << name << ": the link budget gives " << budget_m << " m";
    // At max range the median link is dead; at half of the 50 % distance it is clean.
    EXPECT_GT(PacketErrorRate(p->per, SnrDb(*p, MedianPathLossDb(*p, p->max_range_m))), 0.999);
    EXPECT_LT(PacketErrorRate(p->per, SnrDb(*p, MedianPathLossDb(*p, RangeForPer(*p, 0.5) / 2))), 0.001);
  }
}

// REFERENCES 1.1 [D5]: SiK at 64 kbit/s, 12-byte payload, one way: min 9, median 64, p95 117 ms.
TEST(RadioProfile, TelemetryLatencyMatchesTheSikMeasurement) {
  auto p = LoadRadioProfile(testing::TrialsDir() + "/radios/telemetry_900mhz.yaml");
  ASSERT_TRUE(p.ok()) << p.error().ToString();
  Channel ch(*p, 2, 3, {});
  ch.SetPositions(testing::LineUp(2, 1));
  const auto got = testing::SendStream(ch, 3000, 500'000'000, 12);
  ASSERT_EQ(got.size(), 3000u);
  std::vector<double> ms;
  for (const Delivery& d : got) ms.push_back(static_cast<double>(d.at_ns - d.packet.sent_ns) * 1e-6);
  std::sort(ms.begin(), ms.end());
  EXPECT_NEAR(ms.front(), 9.0, 0.5);
  EXPECT_NEAR(ms[ms.size() / 2], 64.0, 5.0);
  EXPECT_NEAR(ms[ms.size() * 95 / 100], 117.0, 5.0);
}

Result<RadioProfile> ParseText(const std::string& text) {
  auto doc = yaml::Parse(text, "bad.yaml");
  if (!doc) return doc.error();
  return ParseRadioProfile(*doc, "bad.yaml");
}

std::string GoodText() {
  return "name: test\n"
         "frequency_mhz: 5180\n"
         "tx_power_dbm: 15\n"
         "antenna_gain_dbi: 0\n"
         "noise_floor_dbm: -91\n"
         "path_loss:\n"
         "  exponent: 2.2\n"
         "  reference_loss_db: 46.7\n"
         "  reference_distance_m: 1\n"
         "  shadowing_sigma_db: 3\n"
         "  decorrelation_m: 20\n"
         "obstacle_loss_db: 20\n"
         "per: {snr50_db: 0.1, width_db: 0.45}\n"
         "max_range_m: 757\n"
         "data_rate_bps: 6500000\n"
         "capacity_bps: 6500000\n"
         "frame_overhead_us: 121.5\n"
         "queue_frames: 50\n";
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(RadioProfile, ParsesAllKeys) {
  auto p = ParseText(GoodText() + "access_wait_max_us: 5000\n");
  ASSERT_TRUE(p.ok()) << p.error().ToString();
  EXPECT_EQ(p->path_loss.exponent, 2.2);
  EXPECT_EQ(p->per.width_db, 0.45);
  EXPECT_EQ(p->queue_frames, 50u);
  EXPECT_EQ(p->access_wait_max_us, 5000.0);
  EXPECT_TRUE(ValidateRadioProfile(*p).ok());
}

TEST(RadioProfile, ABadValueIsReportedWhereItIsWritten) {
  auto p = ParseText(Replace(GoodText(), "exponent: 2.2", "exponent: -1"));
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().where(), "bad.yaml:7:13");
  EXPECT_NE(p.error().message().find("path_loss.exponent"), std::string::npos) << p.error().message();

  p = ParseText(Replace(GoodText(), "width_db: 0.45", "width_db: 0"));
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().where(), "bad.yaml:13:32");
  EXPECT_NE(p.error().message().find("per.width_db must be positive"), std::string::npos) << p.error().message();

  p = ParseText(Replace(GoodText(), "queue_frames: 50", "queue_frames: lots"));
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().where(), "bad.yaml:18:15");
}

TEST(RadioProfile, UnknownAndMissingKeysAreErrors) {
  auto p = ParseText(GoodText() + "bandwidth_mhz: 20\n");
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().where(), "bad.yaml:19:1");
  EXPECT_NE(p.error().message().find("unknown key 'bandwidth_mhz'"), std::string::npos) << p.error().message();

  p = ParseText(Replace(GoodText(), "queue_frames: 50\n", ""));
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.error().message().find("missing required key 'queue_frames'"), std::string::npos)
      << p.error().message();

  p = ParseText(Replace(GoodText(), "  decorrelation_m: 20\n", ""));
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.error().message().find("'decorrelation_m' in path_loss"), std::string::npos) << p.error().message();
  EXPECT_EQ(p.error().where(), "bad.yaml:7:3");
}

TEST(RadioProfile, LoadReportsFileLineColumn) {
  const std::string dir = swarmbox::testing::MakeTempDir("channel_profile_");
  ASSERT_FALSE(dir.empty());
  const std::string path = dir + "/broken.yaml";
  std::ofstream(path) << "name: broken\nfrequency_mhz: [1, 2\n";
  auto p = LoadRadioProfile(path);
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().where().rfind(path + ":", 0), 0u) << p.error().ToString();

  std::ofstream(path) << Replace(GoodText(), "max_range_m: 757", "max_range_m: 0");
  p = LoadRadioProfile(path);
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().where(), path + ":14:14");

  p = LoadRadioProfile(dir + "/absent.yaml");
  EXPECT_FALSE(p.ok());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace swarmbox::channel
