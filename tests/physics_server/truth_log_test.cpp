// truth.csv format and determinism: same world, commands and seed -> byte-identical files.
#include "swarmbox/physics/truth_log.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "test_util.hpp"

namespace swarmbox::physics {
namespace {

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Rubble world (obstacles, gusty wind), three x500s and a lifter with its stretcher, open-loop
// commands that vary with time, a collision with a wall and a crash: everything that could
// break determinism.
std::string RunScenario(std::uint64_t seed, const std::string& path) {
  auto config = LoadWorld(testing::WorldPath("rubble_block"));
  EXPECT_TRUE(config.ok());
  auto world = testing::MakeWorld(*config, seed);
  const Airframe x500 = testing::LoadShippedAirframe("x500");
  const Airframe x8 = testing::LoadShippedAirframe("x8_heavy");
  const double u = x500.HoverRotorSpeed() / x500.motor.max_rot_velocity_rad_s;
  for (int i = 0; i < 3; ++i) {
    testing::Spawn(*world, testing::MakeSpawn("scout_" + std::to_string(i), x500, Vec3{-5.0 + 3 * i, 26.0, 3}, 0.0, u));
  }
  const double u8 = x8.HoverRotorSpeed(x8.payloads[0].mass_kg) / x8.motor.max_rot_velocity_rad_s;
  testing::Spawn(*world, testing::MakeSpawn("lifter", x8, Vec3{40, -40, 10}, 0.0, u8, "stretcher", true));
  CollectingEventSink events;
  world->SetEventSink(&events);
  auto file = TruthCsvFile::Open(path, 50);
  EXPECT_TRUE(file.ok());
  std::vector<double> cmd(4), cmd8(8, u8);
  for (int k = 0; k < 750; ++k) {  // 3 s
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t r = 0; r < 4; ++r) cmd[r] = u * (1.0 + 0.05 * std::sin(0.01 * k * static_cast<double>(i + r + 1)));
      EXPECT_TRUE(world->SetActuators(i, cmd).ok());
    }
    EXPECT_TRUE(world->SetActuators(3, cmd8).ok());
    world->Step();
    EXPECT_TRUE(file->MaybeWrite(*world).ok());
  }
  EXPECT_TRUE(file->Flush().ok());
  std::string log;
  for (const auto& e : events.events) log += e.ToLogEvent().str() + "\n";
  return log;
}

TEST(TruthLog, SameSeedGivesByteIdenticalTruthCsv) {
  const auto dir = std::filesystem::temp_directory_path() / ("swarmbox_truth_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string a = (dir / "a.csv").string(), b = (dir / "b.csv").string(), c = (dir / "c.csv").string();
  const std::string events_a = RunScenario(42, a);
  const std::string events_b = RunScenario(42, b);
  RunScenario(43, c);
  const std::string ta = ReadAll(a), tb = ReadAll(b), tc = ReadAll(c);
  EXPECT_GT(ta.size(), 10'000u);
  EXPECT_EQ(ta, tb);
  EXPECT_EQ(events_a, events_b);
  EXPECT_NE(ta, tc);  // another seed, other gusts
  // 3 s at 50 Hz: a row at the first step (t = 0.004), then at t = 0.02, 0.04 ... 3.0: 151
  // samples x 4 drones, plus the header.
  EXPECT_EQ(std::count(ta.begin(), ta.end(), '\n'), 1 + 151 * 4);
  std::filesystem::remove_all(dir);
}

TEST(TruthLog, RowHasEveryColumn) {
  DroneTruth t;
  t.position_m = {1, 2, 3};
  t.rotor_count = 4;
  t.rotor_speed_rad_s[0] = 770.123;
  const std::string row = TruthCsvRow(1.5, "scout_1", t);
  EXPECT_EQ(row,
            "1.500,scout_1,1.0000,2.0000,3.0000,0.0000,0.0000,0.0000,1.00000,0.00000,0.00000,0.00000,0.00000,"
            "0.00000,0.00000,770.12,0.00,0.00,0.00,,,,,0,0.0000,0,0\n");
  const std::string header = TruthCsvHeader();
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), std::count(row.begin(), row.end(), ','));
}

TEST(TruthLog, UnwritablePathIsAnIoError) {
  auto f = TruthCsvFile::Open("/nonexistent_dir/truth.csv", 10);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.error().code(), ErrorCode::kIo);
  EXPECT_NE(f.error().message().find("cannot open for writing"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::physics
