// One definition of each metric (issue #16): a SAR trial's folder gives the same numbers in
// result.json (the runner's ResultJson over report::ReadTrialMetrics), in its results.csv row
// (report::ReadExperimentFolder + ResultsCsv, as `swarmbox report` writes it) and in its ending
// line (`event=mission_complete victims=N rescued=M`).
//
// SarRunMetrics.ARealRunsFolderAgrees: the logs of a real `swarmbox run trials/sar_search.yaml`
// (data/sar_search, its README says how it was written), also against the result.json its runner
// wrote. SarRunMetrics.ResultJsonResultsCsvAndTheEndingLineAgree: the same on a small folder whose
// lines are in the formats the agents write them (agent/raft/src/mission_state_machine.cpp:
// victim_confirmed/victim_status by `id`, logged by every node as it applies the entry;
// agent/swarm/src/scout_behaviour.cpp: sighting_reported without an id; agent/app/sar_brain.cpp:
// mission_complete victims= rescued=), with the ending line of the example report's trial
// radio-abb-r1 (docs/example-report), whose result.json said victims_confirmed 1 and
// victims_detected 0 before. The same agreement on a real run's logs: cli_sar_search_e2e_test.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/report/results_csv.hpp"
#include "swarmbox/report/trial_record.hpp"
#include "swarmbox/runner/results.hpp"

namespace swarmbox::runner {
namespace {

namespace fs = std::filesystem;

std::string ReadFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

constexpr char kEndingLine[] = "t=257.340 node=scout_3 event=mission_complete victims=2 rescued=2";

// What every drone logs of the mission as it applies the Raft entries.
std::string MissionLines(const std::string& node) {
  const std::string n = " node=" + node + " event=";
  return "t=3.120" + n + "leader_elected term=1 leader=scout_2\n"
         "t=5.400" + n + "mission_state state=search index=3\n"
         "t=66.900" + n + "victim_confirmed id=1 x=42.10 y=-18.30 index=41\n"
         "t=98.500" + n + "victim_status id=1 status=being_rescued rescuer=lifter index=57\n"
         "t=121.700" + n + "victim_confirmed id=2 x=-35.60 y=61.20 index=70\n"
         "t=140.200" + n + "victim_status id=1 status=rescued index=81\n"
         "t=170.800" + n + "victim_status id=2 status=being_rescued rescuer=lifter index=95\n"
         "t=226.400" + n + "victim_status id=2 status=rescued index=118\n"
         "t=230.000" + n + "mission_state state=return index=121\n"
         "t=12.000" + n + "link peer=scout_1 sent=10 received=10 loss=0.0000 rtt_ms_mean=212.4\n"
         "t=22.000" + n + "link peer=scout_1 sent=10 received=9 loss=0.1000 rtt_ms_mean=205.0\n";
}

void WriteSarTrialFolder(const fs::path& trial) {
  fs::create_directories(trial / "logs");
  for (const std::string node : {"scout_1", "scout_2", "scout_3", "lifter"}) {
    std::string log = MissionLines(node);
    if (node == "scout_3") {
      log += "t=65.800 node=scout_3 event=sighting_reported seq=4 x=42.05 y=-18.20 confidence=0.912\n";
      log += std::string(kEndingLine) + "\n";
    } else if (node == "scout_1") {
      log += "t=257.100 node=scout_1 event=mission_complete victims=2 rescued=2\n";
    }
    std::ofstream(trial / "logs" / (node + ".log")) << log;
  }
  std::ofstream(trial / "logs" / "physics.log") << "t=0.000 node=physics event=ready\n";
  std::ofstream(trial / "events.jsonl")
      << R"({"wall_s":0.5,"component":"orchestrator","event":"run","target":"physics","outcome":"success"})"
      << "\n";
}

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> out(1);
  for (char c : line) {
    if (c == ',') {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

// Writes result.json into `trial` (inside the experiment folder `exp`) as the runner does, reads
// the folder back as `swarmbox report` does, and checks that result.json's metrics, the
// results.csv row and the ending line agree. Returns result.json's metrics.
yaml::Node ExpectAgreement(const fs::path& exp, const fs::path& trial, const std::string& ending_line) {
  const auto ending = ParseLogfmt(ending_line);
  // result.json as the runner writes it.
  TrialResult r;
  r.trial = "sar-search";
  r.trial_id = "sar-search";
  r.verdict = dsl::Verdict::Of(dsl::Outcome::kSuccess, "matched 'event=mission_complete'");
  r.ending_line = ending_line;
  auto metrics = report::ReadTrialMetrics(trial.string());
  if (!metrics) {
    ADD_FAILURE() << "no logs in " << trial;
    return yaml::Node::Null();
  }
  r.metrics = *metrics;
  { std::ofstream(trial / "result.json") << ResultJson(r); }
  auto result = yaml::Parse(ReadFile(trial / "result.json"), "result.json");
  const yaml::Node* m = result ? result->Find("metrics") : nullptr;
  if (m == nullptr) {
    ADD_FAILURE() << "no metrics";
    return yaml::Node::Null();
  }

  // results.csv as `swarmbox report` writes it.
  std::vector<std::string> problems;
  const auto records = report::ReadExperimentFolder(exp.string(), &problems);
  EXPECT_EQ(records.size(), 1u);
  EXPECT_TRUE(problems.empty());
  std::istringstream csv(report::ResultsCsv({}, records));
  std::string header_line, row_line;
  std::getline(csv, header_line);
  std::getline(csv, row_line);
  const auto header = Split(header_line);
  const auto row = Split(row_line);
  auto cell = [&](const std::string& column) {
    for (std::size_t i = 0; i < header.size() && i < row.size(); ++i) {
      if (header[i] == column) return row[i];
    }
    ADD_FAILURE() << "no column " << column;
    return std::string("?");
  };

  for (const std::string& name : report::MetricNames()) {
    const yaml::Node* v = m->Find(name);
    if (v == nullptr) {
      ADD_FAILURE() << "result.json has no metric " << name;
      continue;
    }
    EXPECT_EQ(cell(name), v->is_null() ? "" : v->scalar()) << name;
  }
  const auto victims = FindField(ending, "victims");
  const auto rescued = FindField(ending, "rescued");
  if (!victims || !rescued) {
    ADD_FAILURE() << "no victims=/rescued= in " << ending_line;
    return *m;
  }
  EXPECT_EQ(m->Find("victims_confirmed")->scalar(), *victims);
  EXPECT_EQ(m->Find("victims_rescued")->scalar(), *rescued);
  EXPECT_EQ(cell("victims_confirmed"), *victims);
  EXPECT_EQ(cell("victims_rescued"), *rescued);
  return *m;
}

TEST(SarRunMetrics, ResultJsonResultsCsvAndTheEndingLineAgree) {
  const fs::path exp = fs::temp_directory_path() / ("swarmbox-sar-metrics-" + std::to_string(::getpid()));
  fs::remove_all(exp);
  const fs::path trial = exp / "sar-search-run";
  WriteSarTrialFolder(trial);
  const std::string ending_line = kEndingLine;
  const auto ending = ParseLogfmt(ending_line);

  const yaml::Node metrics = ExpectAgreement(exp, trial, ending_line);
  ASSERT_TRUE(metrics.is_mapping());
  const yaml::Node* m = &metrics;
  // mission_time_s is the first mission_complete of any log: at or before the ending line's (the
  // runner ends on the first such line to arrive, not always the earliest in simulated time).
  const double mission_s = *yaml::ScalarAsDouble(m->Find("mission_time_s")->scalar());
  EXPECT_LE(mission_s, *yaml::ScalarAsDouble(*FindField(ending, "t")));
  EXPECT_EQ(mission_s, 257.1);
  EXPECT_EQ(m->Find("first_detection_s")->scalar(), "65.8");
  EXPECT_EQ(m->Find("detections")->scalar(), "2");
  EXPECT_EQ(m->Find("collisions")->scalar(), "0");
  EXPECT_EQ(m->Find("leader_changes")->scalar(), "0");
  EXPECT_TRUE(m->Find("min_separation_m")->is_null());  // no truth.csv here
  fs::remove_all(exp);
}

TEST(SarRunMetrics, ARealRunsFolderAgrees) {
  const fs::path data = fs::path(SWARMBOX_SOURCE_DIR) / "tests/orchestrator/runner/data/sar_search";
  ASSERT_TRUE(fs::exists(data / "logs" / "scout_1.log")) << data;
  const fs::path exp = fs::temp_directory_path() / ("swarmbox-sar-real-" + std::to_string(::getpid()));
  fs::remove_all(exp);
  const fs::path trial = exp / "sar-search-real";
  fs::create_directories(trial);
  fs::copy(data / "logs", trial / "logs", fs::copy_options::recursive);
  fs::copy_file(data / "events.jsonl", trial / "events.jsonl");
  auto written = yaml::Parse(ReadFile(data / "result.json"), "result.json");
  ASSERT_TRUE(written) << written.error().ToString();
  const std::string ending_line = written->Find("ending_line")->scalar();
  EXPECT_EQ(ending_line, "t=255.512 node=scout_2 event=mission_complete victims=2 rescued=2");

  const yaml::Node m = ExpectAgreement(exp, trial, ending_line);
  ASSERT_TRUE(m.is_mapping());
  EXPECT_EQ(m.Find("victims_confirmed")->scalar(), "2");
  EXPECT_EQ(m.Find("victims_rescued")->scalar(), "2");
  // The runner of that run wrote the same values (min_separation_m needs truth.csv, not kept).
  const yaml::Node* runner_metrics = written->Find("metrics");
  ASSERT_NE(runner_metrics, nullptr);
  for (const std::string& name : report::MetricNames()) {
    if (name == "min_separation_m") continue;
    const yaml::Node* a = m.Find(name);
    const yaml::Node* b = runner_metrics->Find(name);
    ASSERT_TRUE(a != nullptr && b != nullptr) << name;
    EXPECT_EQ(a->is_null() ? "" : a->scalar(), b->is_null() ? "" : b->scalar()) << name;
  }
  fs::remove_all(exp);
}

}  // namespace
}  // namespace swarmbox::runner
