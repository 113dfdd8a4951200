// TagCache: the tag of an unchanged spec is found again without packing; any change of a file
// stamp, of the spec or of the entry's text is a miss, never a wrong tag.
#include "swarmbox/images/tag_cache.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace swarmbox::images {
namespace {

namespace fs = std::filesystem;

class TagCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("swarmbox-tag-cache-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "in");
    Write("a.yaml", "a: 1\n");
    Write("b.yaml", "b: 2\n");
    spec_.repository = "swarmbox/test";
    spec_.component = "test";
    spec_.files = {{(dir_ / "in" / "a.yaml").string(), "/etc/a.yaml", 0644},
                   {(dir_ / "in" / "b.yaml").string(), "/etc/b.yaml", 0644}};
    spec_.entrypoint = {"/bin/true"};
  }
  void TearDown() override { fs::remove_all(dir_); }

  void Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / "in" / name, std::ios::binary | std::ios::trunc) << text;
  }
  std::string CacheDir() const { return (dir_ / "cache").string(); }
  PackedContext Pack() {
    auto ctx = PackContext(spec_);
    EXPECT_TRUE(ctx) << ctx.error().ToString();
    return ctx ? *ctx : PackedContext{};
  }

  fs::path dir_;
  ImageSpec spec_;
};

TEST_F(TagCacheTest, AnUnchangedSpecFindsItsTagAgain) {
  TagCache cache(CacheDir());
  EXPECT_FALSE(cache.Lookup(spec_).has_value());  // nothing remembered yet
  const PackedContext ctx = Pack();
  EXPECT_EQ(ctx.host_files.size(), 2u);
  ASSERT_TRUE(cache.Remember(spec_, ctx));
  auto tag = cache.Lookup(spec_);
  ASSERT_TRUE(tag.has_value());
  EXPECT_EQ(*tag, ctx.tag);
}

TEST_F(TagCacheTest, ATouchedOrRewrittenFileIsAMiss) {
  TagCache cache(CacheDir());
  ASSERT_TRUE(cache.Remember(spec_, Pack()));
  // Same content, another mtime.
  const fs::path a = dir_ / "in" / "a.yaml";
  fs::last_write_time(a, fs::last_write_time(a) + std::chrono::seconds(3));
  EXPECT_FALSE(cache.Lookup(spec_).has_value());
  const PackedContext again = Pack();
  ASSERT_TRUE(cache.Remember(spec_, again));
  EXPECT_EQ(cache.Lookup(spec_), again.tag);
  // Another content (another size).
  Write("b.yaml", "b: 22\n");
  EXPECT_FALSE(cache.Lookup(spec_).has_value());
  // A file that went away.
  fs::remove(dir_ / "in" / "b.yaml");
  EXPECT_FALSE(cache.Lookup(spec_).has_value());
}

TEST_F(TagCacheTest, EveryFieldOfTheSpecIsPartOfTheKey) {
  const std::string key = SpecKey(spec_);
  EXPECT_EQ(key, SpecKey(spec_));
  ImageSpec other = spec_;
  other.entrypoint = {"/bin/false"};
  EXPECT_NE(SpecKey(other), key);
  other = spec_;
  other.env["MODE"] = "x";
  EXPECT_NE(SpecKey(other), key);
  other = spec_;
  other.files[0].image_path = "/etc/a2.yaml";
  EXPECT_NE(SpecKey(other), key);
  other = spec_;
  other.strip_debug = !other.strip_debug;
  EXPECT_NE(SpecKey(other), key);
  // A remembered spec does not answer for a changed one.
  TagCache cache(CacheDir());
  ASSERT_TRUE(cache.Remember(spec_, Pack()));
  other = spec_;
  other.user = "0:0";
  EXPECT_FALSE(cache.Lookup(other).has_value());
}

TEST_F(TagCacheTest, EntriesRoundTripAndBrokenOnesAreMisses) {
  TagCacheEntry entry{"swarmbox/x:0123456789abcdef",
                      {{"/a b/with space", 10, 1234567890123, 42}, {"/c", 0, 1, 2}}};
  auto back = ParseTagCacheEntry(FormatTagCacheEntry(entry));
  ASSERT_TRUE(back) << back.error().ToString();
  EXPECT_EQ(back->tag, entry.tag);
  EXPECT_EQ(back->files, entry.files);
  for (const char* bad : {"", "tag\n", "tag notag\n", "tag a:b\nfile 1 2\n", "tag a:b\nfile 1 2 3 \n",
                          "tag a:b\nfiles 1 2 3 /x\n"}) {
    SCOPED_TRACE(bad);
    auto r = ParseTagCacheEntry(bad);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code(), ErrorCode::kProtocol);
  }
  // A corrupt entry on disk is a miss.
  TagCache cache(CacheDir());
  ASSERT_TRUE(cache.Remember(spec_, Pack()));
  std::ofstream(fs::path(CacheDir()) / (SpecKey(spec_) + ".tag"), std::ios::trunc) << "garbage";
  EXPECT_FALSE(cache.Lookup(spec_).has_value());
}

TEST_F(TagCacheTest, NoDirectoryMeansNoCaching) {
  TagCache cache("");
  EXPECT_TRUE(cache.Remember(spec_, Pack()));
  EXPECT_FALSE(cache.Lookup(spec_).has_value());
}

}  // namespace
}  // namespace swarmbox::images
