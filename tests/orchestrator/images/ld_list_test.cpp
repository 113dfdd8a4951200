#include "swarmbox/images/ld_list.hpp"

#include <gtest/gtest.h>

namespace swarmbox::images {
namespace {

// Recorded: `/lib64/ld-linux-x86-64.so.2 --list /usr/sbin/tc` on Debian 12.
constexpr char kTcList[] =
    "\tlinux-vdso.so.1 (0x00007f25ba096000)\n"
    "\tlibbpf.so.1 => /lib/x86_64-linux-gnu/libbpf.so.1 (0x00007f25b9f89000)\n"
    "\tlibelf.so.1 => /lib/x86_64-linux-gnu/libelf.so.1 (0x00007f25b9f6e000)\n"
    "\tlibmnl.so.0 => /lib/x86_64-linux-gnu/libmnl.so.0 (0x00007f25b9f66000)\n"
    "\tlibbsd.so.0 => /lib/x86_64-linux-gnu/libbsd.so.0 (0x00007f25b9f50000)\n"
    "\tlibcap.so.2 => /lib/x86_64-linux-gnu/libcap.so.2 (0x00007f25b9f44000)\n"
    "\tlibm.so.6 => /lib/x86_64-linux-gnu/libm.so.6 (0x00007f25b9e62000)\n"
    "\tlibxtables.so.12 => /lib/x86_64-linux-gnu/libxtables.so.12 (0x00007f25b9e4e000)\n"
    "\tlibc.so.6 => /lib/x86_64-linux-gnu/libc.so.6 (0x00007f25b9c6c000)\n"
    "\tlibz.so.1 => /lib/x86_64-linux-gnu/libz.so.1 (0x00007f25b9c4d000)\n"
    "\t/lib64/ld-linux-x86-64.so.2 (0x00007f25ba098000)\n"
    "\tlibmd.so.0 => /lib/x86_64-linux-gnu/libmd.so.0 (0x00007f25b9c40000)\n";

TEST(LdList, ParsesTheRecordedListOfTc) {
  auto entries = ParseLdList(kTcList);
  ASSERT_TRUE(entries) << entries.error().ToString();
  ASSERT_EQ(entries->size(), 11u);  // vdso left out
  EXPECT_EQ((*entries)[0].name, "libbpf.so.1");
  EXPECT_EQ((*entries)[0].path, "/lib/x86_64-linux-gnu/libbpf.so.1");
  EXPECT_EQ((*entries)[9].path, "/lib64/ld-linux-x86-64.so.2");
  EXPECT_EQ((*entries)[10].name, "libmd.so.0");
}

TEST(LdList, KeepsUnresolvedLibrariesWithAnEmptyPath) {
  auto entries = ParseLdList("\tlibfoo.so.1 => not found\n\tlibc.so.6 => /lib/libc.so.6 (0x1)\n");
  ASSERT_TRUE(entries) << entries.error().ToString();
  ASSERT_EQ(entries->size(), 2u);
  EXPECT_EQ((*entries)[0].name, "libfoo.so.1");
  EXPECT_TRUE((*entries)[0].path.empty());
}

TEST(LdList, RejectsOutputOfAnotherShape) {
  auto entries = ParseLdList("\tnot a dynamic executable\n");
  ASSERT_FALSE(entries);
  EXPECT_EQ(entries.error().code(), ErrorCode::kProtocol);
  EXPECT_EQ(entries.error().message(), "unexpected loader output line: 'not a dynamic executable'");
}

}  // namespace
}  // namespace swarmbox::images
