// The experiment folder: atomic commits, resume that never loses or repeats a trial, the folder
// lock, and the progress board.
#include "swarmbox/experiment/trial_store.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include "swarmbox/experiment/experiment_runner.hpp"
#include "swarmbox/experiment/progress.hpp"
#include "swarmbox/experiment/scheduler.hpp"

namespace swarmbox::experiment {
namespace {

namespace fs = std::filesystem;

class TrialStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("swarmbox-store-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  static std::string Read(const fs::path& p) {
    std::ifstream in(p);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  fs::path dir_;
};

TEST_F(TrialStoreTest, CommitMovesTheWholeFolderOnceAndOnlyWithAResult) {
  TrialStore store(dir_.string());
  auto staging = store.Staging("exp-a-r1", 1);
  ASSERT_TRUE(staging);
  const fs::path run = fs::path(*staging) / "exp-a-r1-run";
  fs::create_directories(run / "logs");
  std::ofstream(run / "logs" / "physics.log") << "t=1.000 node=physics event=ready\n";
  Status without = store.Commit("exp-a-r1", run.string());
  ASSERT_FALSE(without);
  EXPECT_EQ(without.error().message(), "refusing to commit a trial without result.json");
  EXPECT_FALSE(store.Done("exp-a-r1"));

  ASSERT_TRUE(WriteFileAtomic((run / "result.json").string(), "{\"outcome\":\"success\"}"));
  ASSERT_TRUE(store.Commit("exp-a-r1", run.string()));
  EXPECT_TRUE(store.Done("exp-a-r1"));
  EXPECT_EQ(Read(dir_ / "exp-a-r1" / "logs" / "physics.log"), "t=1.000 node=physics event=ready\n");
  EXPECT_FALSE(fs::exists(run));

  // A second commit of the same trial is refused: it is never recorded twice.
  auto again = store.Staging("exp-a-r1", 2);
  ASSERT_TRUE(again);
  ASSERT_TRUE(WriteFileAtomic((fs::path(*again) / "result.json").string(), "{}"));
  Status twice = store.Commit("exp-a-r1", *again);
  ASSERT_FALSE(twice);
  EXPECT_EQ(twice.error().code(), ErrorCode::kAlreadyExists);
  EXPECT_EQ(Read(dir_ / "exp-a-r1" / "result.json"), "{\"outcome\":\"success\"}");
}

TEST_F(TrialStoreTest, WriteFileAtomicReplacesAndLeavesNoTemporary) {
  const fs::path f = dir_ / "result.json";
  ASSERT_TRUE(WriteFileAtomic(f.string(), "first"));
  ASSERT_TRUE(WriteFileAtomic(f.string(), "second"));
  EXPECT_EQ(Read(f), "second");
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) ++files;
  EXPECT_EQ(files, 1);
}

TEST_F(TrialStoreTest, TheFolderLockIsExclusive) {
  auto first = DirLock::Acquire(dir_.string());
  ASSERT_TRUE(first);
  auto second = DirLock::Acquire(dir_.string());
  ASSERT_FALSE(second);
  EXPECT_EQ(second.error().code(), ErrorCode::kUnavailable);
}

// A host that commits each trial through the store like the real executor, counts runs per trial,
// and "crashes" the orchestrator (sets the interrupt) after `crash_after` commits; the attempt in
// flight at that moment is left in staging, as a killed process would leave it.
class StoreHost final : public HostWorker {
 public:
  StoreHost(TrialStore& store, std::atomic<bool>& crash, int crash_after)
      : store_(store), crash_(crash), crash_after_(crash_after) {}
  std::string name() const override { return "local"; }
  int slots() const override { return 2; }
  AttemptResult Run(const PlannedTrial& t, int attempt) override {
    {
      std::lock_guard lock(mu_);
      runs_[t.id] += 1;
    }
    auto staging = store_.Staging(t.id, attempt);
    if (!staging) return {AttemptResult::Kind::kHostFailed, "", staging.error().ToString()};
    const fs::path run = fs::path(*staging) / (t.id + "-run");
    fs::create_directories(run);
    if (crash_.load()) return {AttemptResult::Kind::kCancelled, "", "crashed"};
    (void)WriteFileAtomic((run / "result.json").string(), "{\"trial\":\"" + t.id + "\"}");
    if (!store_.Commit(t.id, run.string())) {
      return {AttemptResult::Kind::kHostFailed, "", "commit failed"};
    }
    {
      std::lock_guard lock(mu_);
      committed_.push_back(t.id);
    }
    if (++commits_ >= crash_after_) crash_.store(true);
    return {AttemptResult::Kind::kCompleted, "success", ""};
  }
  std::map<std::string, int> runs() {
    std::lock_guard lock(mu_);
    return runs_;
  }
  std::vector<std::string> committed() {
    std::lock_guard lock(mu_);
    return committed_;
  }

 private:
  TrialStore& store_;
  std::atomic<bool>& crash_;
  int crash_after_;
  std::atomic<int> commits_{0};
  std::mutex mu_;
  std::map<std::string, int> runs_;
  std::vector<std::string> committed_;
};

TEST_F(TrialStoreTest, ResumeRunsOnlyWhatHasNoResultAndNeverATrialTwice) {
  std::vector<PlannedTrial> all;
  for (int i = 0; i < 9; ++i) {
    PlannedTrial t;
    t.id = "exp-" + std::string(1, static_cast<char>('a' + i)) + "-r1";
    all.push_back(t);
  }
  TrialStore store(dir_.string());
  ScheduleObserver quiet;

  // First run: crashes after 4 commits.
  std::atomic<bool> crash{false};
  StoreHost first(store, crash, 4);
  RunSchedule(store.Pending(all), {&first}, {.max_attempts = 3, .interrupted = &crash}, quiet);
  const auto pending = store.Pending(all);
  const std::size_t committed_first = all.size() - pending.size();
  EXPECT_GE(committed_first, 4u);
  EXPECT_LT(committed_first, all.size());

  // Resume: staging is cleared, only the rest runs.
  ASSERT_TRUE(store.ClearStaging());
  EXPECT_FALSE(fs::exists(dir_ / ".staging"));
  std::atomic<bool> never{false};
  StoreHost second(store, never, 1000);
  auto reports = RunSchedule(pending, {&second}, {.max_attempts = 3, .interrupted = &never}, quiet);
  for (const TrialReport& r : reports) EXPECT_EQ(r.status, TrialStatus::kCompleted);

  for (const PlannedTrial& t : all) {
    EXPECT_TRUE(store.Done(t.id)) << t.id;
    EXPECT_EQ(Read(dir_ / t.id / "result.json"), "{\"trial\":\"" + t.id + "\"}");
    // Committed exactly once over both sessions; a trial committed by the first session is never
    // handed to the second (one cut short by the crash, uncommitted, is run again).
    const auto c1 = first.committed();
    const auto c2 = second.committed();
    const auto n1 = std::count(c1.begin(), c1.end(), t.id);
    const auto n2 = std::count(c2.begin(), c2.end(), t.id);
    EXPECT_EQ(n1 + n2, 1) << t.id;
    if (n1 == 1) {
      EXPECT_EQ(second.runs().count(t.id), 0u) << t.id << " ran again after its commit";
    }
  }
  EXPECT_TRUE(store.Pending(all).empty());
}

TEST(ProgressBoard, LinesPerHostAndAnOverallBarWithEta) {
  ProgressBoard board({{"local", 2}, {"root@10.250.0.2", 1}}, 8, 2);
  board.Started("local", "e-aa-r1", 0);
  board.Started("root@10.250.0.2", "e-ab-r1", 0);
  board.Finished("local", "e-aa-r1", "success", 30);
  board.Started("local", "e-ba-r1", 30);
  board.Finished("root@10.250.0.2", "e-ab-r1", "", 35);  // lost with its host
  board.HostDown("root@10.250.0.2", "dockerd gone");
  auto lines = board.Render(40);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "local            2 slots  up    done 1  running e-ba-r1 10s");
  EXPECT_EQ(lines[1], "root@10.250.0.2  1 slot   DOWN  done 0  (dockerd gone)");
  // 3 of 8 done, 5 left on 2 slots up at 30 s a trial: 3 waves = 1m30s.
  EXPECT_EQ(lines[2],
            "[#######.............] 3/8  success 1 failure 0 timeout 0 error 0 | running 1 | "
            "requeued 1 | ETA 1m30s");
  EXPECT_EQ(FormatDuration(3725), "1h02m");
}

}  // namespace
}  // namespace swarmbox::experiment

namespace swarmbox::experiment {
namespace {

TEST_F(TrialStoreTest, TheOutputFolderTakesOnlyItsOwnExperimentAndResumesOnlyWhenAsked) {
  ExperimentPlan plan;
  plan.spec.name = "hover";
  PlannedTrial t;
  t.id = "hover-a-r1";
  plan.trials = {t};
  // A new folder: no earlier runs.
  auto fresh = CheckOutFolder(plan, dir_.string(), /*resume=*/false);
  ASSERT_TRUE(fresh) << fresh.error().ToString();
  EXPECT_TRUE(fresh->empty());

  ASSERT_TRUE(WriteFileAtomic((dir_ / "experiment.json").string(),
                              R"({"name":"hover","run_ids":["r1","r2"]})"));
  fs::create_directories(dir_ / "hover-a-r1");
  ASSERT_TRUE(WriteFileAtomic((dir_ / "hover-a-r1" / "result.json").string(), "{}"));
  auto again = CheckOutFolder(plan, dir_.string(), /*resume=*/false);
  ASSERT_FALSE(again);
  EXPECT_NE(again.error().message().find("add --resume"), std::string::npos);
  auto resumed = CheckOutFolder(plan, dir_.string(), /*resume=*/true);
  ASSERT_TRUE(resumed);
  EXPECT_EQ(*resumed, (std::vector<std::string>{"r1", "r2"}));

  plan.spec.name = "radio";
  auto other = CheckOutFolder(plan, dir_.string(), /*resume=*/true);
  ASSERT_FALSE(other);
  EXPECT_NE(other.error().message().find("holds another experiment ('hover')"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::experiment
