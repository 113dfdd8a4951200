// WalStorage on real temporary directories, with write/fsync failures injected through the
// FileSystem interface.
#include "swarmbox/raft/wal_storage.hpp"

#include "swarmbox/raft/conf_change.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>

namespace swarmbox::raft {
namespace {

namespace fs = std::filesystem;

// The real file system with switches to make appends, fsyncs or atomic writes fail (EIO-like).
class FaultyFileSystem final : public FileSystem {
 public:
  bool fail_append = false;
  bool fail_sync = false;
  std::string fail_atomic_suffix;  // WriteFileAtomic of a path ending so fails

  Status CreateDirs(const std::string& p) override { return real_.CreateDirs(p); }
  Result<Bytes> ReadFile(const std::string& p) override { return real_.ReadFile(p); }
  Status Truncate(const std::string& p, std::uint64_t n) override { return real_.Truncate(p, n); }
  Status WriteFileAtomic(const std::string& p, std::span<const std::uint8_t> b) override {
    if (!fail_atomic_suffix.empty() && p.ends_with(fail_atomic_suffix)) {
      return Error(ErrorCode::kIo, "write: Input/output error (injected)", p + ".tmp");
    }
    return real_.WriteFileAtomic(p, b);
  }
  Result<std::unique_ptr<AppendFile>> OpenAppend(const std::string& p) override {
    auto f = real_.OpenAppend(p);
    if (!f) return f.error();
    return std::unique_ptr<AppendFile>(std::make_unique<File>(*this, std::move(*f), p));
  }

 private:
  class File final : public AppendFile {
   public:
    File(FaultyFileSystem& fs, std::unique_ptr<AppendFile> f, std::string p)
        : fs_(fs), f_(std::move(f)), path_(std::move(p)) {}
    Status Append(std::span<const std::uint8_t> b) override {
      if (fs_.fail_append) {
        // A short write: half the bytes reach the file, as a full disk would leave them.
        (void)f_->Append(b.first(b.size() / 2));
        return Error(ErrorCode::kIo, "write: No space left on device (injected)", path_);
      }
      return f_->Append(b);
    }
    Status Sync() override {
      if (fs_.fail_sync) return Error(ErrorCode::kIo, "fsync: Input/output error (injected)", path_);
      return f_->Sync();
    }

   private:
    FaultyFileSystem& fs_;
    std::unique_ptr<AppendFile> f_;
    std::string path_;
  };
  PosixFileSystem real_;
};

Entry Ent(std::uint64_t index, std::uint64_t term, std::string_view data = "d") {
  return Entry{term, index, EntryType::kNormal, Bytes(data.begin(), data.end())};
}

class WalStorageTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "swarmbox-wal-XXXXXX").string();
    ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::unique_ptr<WalStorage> Open(FileSystem& f) {
    auto w = WalStorage::Open(f, dir_);
    EXPECT_TRUE(w.ok()) << (w.ok() ? "" : w.error().ToString());
    return w.ok() ? std::move(*w) : nullptr;
  }
  PersistentState Reload() {
    PosixFileSystem f;
    auto w = Open(f);
    return w ? *w->Load() : PersistentState{};
  }
  void AppendRawToWal(const Bytes& b) {
    std::ofstream out(dir_ + "/wal", std::ios::binary | std::ios::app);
    out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
  }

  std::string dir_;
  PosixFileSystem posix_;
};

TEST_F(WalStorageTest, FreshDirectoryLoadsEmptyState) {
  auto w = Open(posix_);
  auto st = w->Load();
  ASSERT_TRUE(st.ok());
  EXPECT_EQ(st->hard_state, HardState{});
  EXPECT_TRUE(st->entries.empty());
  EXPECT_TRUE(st->snapshot.empty());
}

TEST_F(WalStorageTest, SavedStateSurvivesReopen) {
  {
    auto w = Open(posix_);
    std::vector<Entry> e = {Ent(1, 1), Ent(2, 1, "two")};
    ASSERT_TRUE(w->Save(HardState{1, 2, 1}, e, {}).ok());
    ASSERT_TRUE(w->Save(HardState{2, 3, 2}, {}, {}).ok());
  }
  PersistentState st = Reload();
  EXPECT_EQ(st.hard_state, (HardState{2, 3, 2}));
  ASSERT_EQ(st.entries.size(), 2u);
  EXPECT_EQ(st.entries[1], Ent(2, 1, "two"));
}

// Raft §5.3: entries written again from index i replace the stored suffix from i.
TEST_F(WalStorageTest, RewrittenSuffixReplacesOldEntries) {
  {
    auto w = Open(posix_);
    std::vector<Entry> e = {Ent(1, 1), Ent(2, 1), Ent(3, 1)};
    ASSERT_TRUE(w->Save(HardState{1, 0, 0}, e, {}).ok());
    std::vector<Entry> e2 = {Ent(2, 2, "new")};
    ASSERT_TRUE(w->Save(HardState{2, 0, 0}, e2, {}).ok());
  }
  PersistentState st = Reload();
  ASSERT_EQ(st.entries.size(), 2u);
  EXPECT_EQ(st.entries[1], Ent(2, 2, "new"));
}

TEST_F(WalStorageTest, TornTailIsCutOffOnReload) {
  {
    auto w = Open(posix_);
    std::vector<Entry> e = {Ent(1, 1), Ent(2, 1)};
    ASSERT_TRUE(w->Save(HardState{1, 1, 1}, e, {}).ok());
  }
  const auto clean_size = fs::file_size(dir_ + "/wal");
  // A record header promising 100 bytes, followed by only 3 of them (a crash mid-write).
  AppendRawToWal(Bytes{100, 0, 0, 0, 1, 2, 3, 4, 9, 9, 9});
  {
    auto w = Open(posix_);
    EXPECT_EQ(w->torn_bytes_dropped(), 11u);
    EXPECT_EQ(w->Load()->entries.size(), 2u);
    EXPECT_EQ(fs::file_size(dir_ + "/wal"), clean_size);
    // The node goes on writing after the cut.
    std::vector<Entry> e = {Ent(3, 1)};
    ASSERT_TRUE(w->Save(std::nullopt, e, {}).ok());
  }
  EXPECT_EQ(Reload().entries.size(), 3u);
}

TEST_F(WalStorageTest, TornLastRecordWithBadChecksumIsCutOff) {
  {
    auto w = Open(posix_);
    std::vector<Entry> e = {Ent(1, 1)};
    ASSERT_TRUE(w->Save(HardState{1, 1, 0}, e, {}).ok());
    std::vector<Entry> e2 = {Ent(2, 1, "last")};
    ASSERT_TRUE(w->Save(std::nullopt, e2, {}).ok());
  }
  // Damage the last byte of the file (the last record's payload).
  fs::resize_file(dir_ + "/wal", fs::file_size(dir_ + "/wal") - 1);
  AppendRawToWal(Bytes{0xEE});
  PersistentState st = Reload();
  EXPECT_EQ(st.entries.size(), 1u);
}

// A Save torn after its entries but before its hard state: the reload takes the entries' term.
TEST_F(WalStorageTest, TornSaveBeforeHardStateTakesTheEntriesTerm) {
  {
    auto w = Open(posix_);
    std::vector<Entry> e = {Ent(1, 1)};
    ASSERT_TRUE(w->Save(HardState{1, 2, 1}, e, {}).ok());
    std::vector<Entry> e2 = {Ent(2, 3)};
    ASSERT_TRUE(w->Save(HardState{3, 0, 1}, e2, {}).ok());
  }
  // Cut the last record (the term-3 hard state) in half.
  fs::resize_file(dir_ + "/wal", fs::file_size(dir_ + "/wal") - 3);
  PosixFileSystem f;
  auto w = Open(f);
  EXPECT_GT(w->torn_bytes_dropped(), 0u);
  PersistentState st = *w->Load();
  ASSERT_EQ(st.entries.size(), 2u);
  EXPECT_EQ(st.hard_state.term, 3u);
  EXPECT_EQ(st.hard_state.vote, kNoNode);
  EXPECT_EQ(st.hard_state.commit, 1u);
}

TEST_F(WalStorageTest, CorruptionBeforeTheTailIsAnError) {
  {
    auto w = Open(posix_);
    std::vector<Entry> e = {Ent(1, 1), Ent(2, 1)};
    ASSERT_TRUE(w->Save(HardState{1, 1, 1}, e, {}).ok());
  }
  {
    std::fstream f(dir_ + "/wal", std::ios::binary | std::ios::in | std::ios::out);
    f.seekp(9);  // inside the first record's payload
    f.put('\x7f');
  }
  auto w = WalStorage::Open(posix_, dir_);
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.error().code(), ErrorCode::kProtocol);
  EXPECT_NE(w.error().message().find("corrupt record at byte 0 (crc mismatch) followed by more "
                                     "records: not a torn write"),
            std::string::npos)
      << w.error().ToString();
  EXPECT_EQ(w.error().where(), dir_ + "/wal");
}

TEST_F(WalStorageTest, CompactionKeepsSnapshotAndLaterEntries) {
  {
    auto w = Open(posix_);
    std::vector<Entry> e = {Ent(1, 1), Ent(2, 1), Ent(3, 2), Ent(4, 2)};
    ASSERT_TRUE(w->Save(HardState{2, 1, 4}, e, {}).ok());
    ASSERT_TRUE(w->Compact(Snapshot{3, 2, Bytes{5, 5}}).ok());
    std::vector<Entry> e2 = {Ent(5, 2)};
    ASSERT_TRUE(w->Save(std::nullopt, e2, {}).ok());
  }
  PersistentState st = Reload();
  EXPECT_EQ(st.snapshot, (Snapshot{3, 2, Bytes{5, 5}}));
  ASSERT_EQ(st.entries.size(), 2u);
  EXPECT_EQ(st.entries[0].index, 4u);
  EXPECT_EQ(st.hard_state, (HardState{2, 1, 4}));
}

// The membership survives a restart: conf-change entries are stored with their type, and a
// snapshot keeps the configuration in effect at its index (conf_change.hpp).
TEST_F(WalStorageTest, MembershipSurvivesReopen) {
  const ConfState conf{{1, 2, 5}, {3, 4, 6}};
  Entry change{2, 5, EntryType::kConfChange, EncodeConfChange({ConfChangeOp::kPromoteLearner, 5})};
  {
    auto w = Open(posix_);
    std::vector<Entry> e = {Ent(1, 1), Ent(2, 1), Ent(3, 2), Ent(4, 2), change};
    ASSERT_TRUE(w->Save(HardState{2, 1, 5}, e, {}).ok());
    ASSERT_TRUE(w->Compact(Snapshot{3, 2, Bytes{5, 5}, conf}).ok());
  }
  PersistentState st = Reload();
  EXPECT_EQ(st.snapshot.conf, conf);
  ASSERT_EQ(st.entries.size(), 2u);
  EXPECT_EQ(st.entries[1], change);
}

TEST_F(WalStorageTest, SnapshotFromLeaderReplacesTheLog) {
  {
    auto w = Open(posix_);
    std::vector<Entry> e = {Ent(1, 1), Ent(2, 1)};
    ASSERT_TRUE(w->Save(HardState{1, 1, 1}, e, {}).ok());
    std::vector<Entry> after = {Ent(11, 3)};
    ASSERT_TRUE(w->Save(HardState{3, 0, 10}, after, Snapshot{10, 3, Bytes{1}}).ok());
  }
  PersistentState st = Reload();
  EXPECT_EQ(st.snapshot.index, 10u);
  ASSERT_EQ(st.entries.size(), 1u);
  EXPECT_EQ(st.entries[0].index, 11u);
  EXPECT_EQ(st.hard_state.commit, 10u);
}

// A crash after the snapshot file is written but before the WAL is rewritten: the reload takes
// the snapshot and the WAL entries after it.
TEST_F(WalStorageTest, CrashBetweenSnapshotAndWalRewriteRecovers) {
  FaultyFileSystem faulty;
  {
    auto w = Open(faulty);
    std::vector<Entry> e = {Ent(1, 1), Ent(2, 1), Ent(3, 1)};
    ASSERT_TRUE(w->Save(HardState{1, 1, 3}, e, {}).ok());
    faulty.fail_atomic_suffix = "/wal";
    Status s = w->Compact(Snapshot{2, 1, Bytes{7}});
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message().find("rewriting raft wal"), std::string::npos);
  }
  PersistentState st = Reload();
  EXPECT_EQ(st.snapshot.index, 2u);
  ASSERT_EQ(st.entries.size(), 1u);
  EXPECT_EQ(st.entries[0].index, 3u);
}

TEST_F(WalStorageTest, WriteFailureFailsTheStorageForGood) {
  FaultyFileSystem faulty;
  auto w = Open(faulty);
  faulty.fail_append = true;
  std::vector<Entry> e = {Ent(1, 1, std::string(64, 'x'))};
  Status s = w->Save(HardState{1, 1, 0}, e, {});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code(), ErrorCode::kIo);
  EXPECT_EQ(s.error().message(),
            "appending to raft wal: write: No space left on device (injected)");
  // Even once the disk recovers, the storage refuses: its durable state is unknown.
  faulty.fail_append = false;
  Status again = w->Save(HardState{1, 1, 0}, {}, {});
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.error().message(), s.error().message());
  // The half-written record is a torn tail for the next start.
  w.reset();
  auto reopened = Open(posix_);
  EXPECT_GT(reopened->torn_bytes_dropped(), 0u);
  EXPECT_TRUE(reopened->Load()->entries.empty());
}

TEST_F(WalStorageTest, FsyncFailureFailsTheStorage) {
  FaultyFileSystem faulty;
  auto w = Open(faulty);
  faulty.fail_sync = true;
  std::vector<Entry> e = {Ent(1, 1)};
  Status s = w->Save(HardState{1, 1, 0}, e, {});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().message(), "syncing raft wal: fsync: Input/output error (injected)");
  EXPECT_FALSE(w->Load().ok());
}

}  // namespace
}  // namespace swarmbox::raft
