#include "swarmbox/docker/tar_archive.hpp"

#include <gtest/gtest.h>

#include "test_data.hpp"

namespace swarmbox::docker {
namespace {

TEST(TarArchive, RoundTripsFilesDirectoriesAndSymlinks) {
  TarWriter w;
  ASSERT_TRUE(w.AddDirectory("tmp", 01777));
  ASSERT_TRUE(w.AddFile("/etc/passwd", "swarmbox:x:1000:1000::/tmp:/sbin/nologin\n", 0644));
  ASSERT_TRUE(w.AddFile("usr/sbin/xtables-nft-multi", std::string(100000, '\x7f'), 0755));
  ASSERT_TRUE(w.AddSymlink("usr/sbin/iptables", "xtables-nft-multi"));
  auto bytes = w.Finish();
  ASSERT_TRUE(bytes) << bytes.error().ToString();
  auto entries = ReadTar(*bytes);
  ASSERT_TRUE(entries) << entries.error().ToString();
  ASSERT_EQ(entries->size(), 4u);
  EXPECT_EQ((*entries)[0].type, TarEntry::Type::kDirectory);
  EXPECT_EQ((*entries)[0].mode, 01777u);
  EXPECT_EQ((*entries)[1].path, "etc/passwd");
  EXPECT_EQ((*entries)[1].content, "swarmbox:x:1000:1000::/tmp:/sbin/nologin\n");
  EXPECT_EQ((*entries)[2].content.size(), 100000u);
  EXPECT_EQ((*entries)[2].mode, 0755u);
  EXPECT_EQ((*entries)[3].type, TarEntry::Type::kSymlink);
  EXPECT_EQ((*entries)[3].content, "xtables-nft-multi");
}

TEST(TarArchive, CarriesExtendedAttributes) {
  TarEntry tool;
  tool.path = "usr/sbin/tc";
  tool.content = "ELF";
  tool.mode = 0755;
  tool.xattrs["security.capability"] = std::string("\x01\x00\x00\x02\x00\x10\x00\x00", 8);
  TarWriter w;
  ASSERT_TRUE(w.Add(tool));
  auto bytes = w.Finish();
  ASSERT_TRUE(bytes) << bytes.error().ToString();
  EXPECT_NE(bytes->find("SCHILY.xattr.security.capability"), std::string::npos);
  auto entries = ReadTar(*bytes);
  ASSERT_TRUE(entries) << entries.error().ToString();
  ASSERT_EQ(entries->size(), 1u);
  EXPECT_EQ((*entries)[0].xattrs, tool.xattrs);
}

TEST(TarArchive, EqualInputsGiveByteEqualArchives) {
  auto make = [] {
    TarWriter w;
    EXPECT_TRUE(w.AddFile("a", "1"));
    EXPECT_TRUE(w.AddFile("b/c", "2"));
    return *w.Finish();
  };
  EXPECT_EQ(make(), make());
}

TEST(TarArchive, ReadsTheRecordedArchiveEndpointAnswer) {
  // GET /containers/{id}/archive?path=/tmp/note.txt, recorded from Docker 20.10.
  auto entries = ReadTar(testing::ReadData("archive_get_note.tar"));
  ASSERT_TRUE(entries) << entries.error().ToString();
  ASSERT_EQ(entries->size(), 1u);
  EXPECT_EQ((*entries)[0].path, "note.txt");
  EXPECT_EQ((*entries)[0].content, "hello from the test\n");
}

TEST(TarArchive, RejectsGarbage) {
  auto entries = ReadTar("this is not a tar archive at all, not even close............");
  ASSERT_FALSE(entries);
  EXPECT_EQ(entries.error().code(), ErrorCode::kProtocol);
  EXPECT_FALSE(entries.error().message().empty());
}

TEST(TarArchive, RefusesAnEmptyPath) {
  TarWriter w;
  Status s = w.AddFile("/", "x");
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().message(), "tar entry with an empty path");
}

}  // namespace
}  // namespace swarmbox::docker
