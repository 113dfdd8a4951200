// The Markdown readers of the docs tests (pure): links, heading anchors, shell command lines.
#include "markdown.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace swarmbox::docs {
namespace {

using ::testing::ElementsAre;

std::vector<std::string> Targets(std::string_view text) {
  std::vector<std::string> out;
  for (const MarkdownLink& l : MarkdownLinks(text)) out.push_back(std::to_string(l.line) + ":" + l.target);
  return out;
}

TEST(MarkdownLinks, FindsInlineImageReferenceAndHtmlLinks) {
  EXPECT_THAT(Targets("See [the map](ARCHITECTURE.md) and ![a plot](docs/p.svg \"title\").\n"
                      "[ref]: <other dir/x.md>\n"
                      "<img src=\"docs/t.png\" width=\"4\"> <a href=\"#status\">s</a>\n"
                      "[web](https://example.org/a_(b)) [here](#quick-start)\n"),
              ElementsAre("1:ARCHITECTURE.md", "1:docs/p.svg", "2:other dir/x.md", "3:docs/t.png",
                          "3:#status", "4:https://example.org/a_(b)", "4:#quick-start"));
}

TEST(MarkdownLinks, IgnoresCodeBlocksAndCodeSpans) {
  EXPECT_THAT(Targets("```sh\necho [x](../outside.md)\n```\nnot `[y](../z.md)` but [w](w.md)\n"),
              ElementsAre("4:w.md"));
}

TEST(HeadingAnchors, AreGitHubsSlugsWithDuplicatesNumbered) {
  EXPECT_EQ(HeadingSlug("Status (2026-11-21)"), "status-2026-11-21");
  EXPECT_EQ(HeadingSlug("Quick start (fresh Debian 12 machine, as root)"),
            "quick-start-fresh-debian-12-machine-as-root");
  EXPECT_EQ(HeadingSlug("`swarmbox run`: one_trial"), "swarmbox-run-one_trial");
  EXPECT_EQ(HeadingAnchors("# A\n## Notes\n```\n# not a heading\n```\n### Notes ##\n#nospace\n"),
            (std::set<std::string>{"a", "notes", "notes-1"}));
}

TEST(SplitShellWords, QuotesEscapesCommentsAndGlobs) {
  auto words = SplitShellWords(
      "swarmbox experiment t/*.yaml --hosts 'local?slots=2' --filter \"a??\" a\\ b x#y   # note");
  ASSERT_TRUE(words) << words.error().ToString();
  std::vector<std::string> texts;
  std::vector<bool> globs;
  for (const ShellWord& w : *words) {
    texts.push_back(w.text);
    globs.push_back(w.glob);
  }
  EXPECT_THAT(texts, ElementsAre("swarmbox", "experiment", "t/*.yaml", "--hosts", "local?slots=2",
                                 "--filter", "a??", "a b", "x#y"));
  EXPECT_THAT(globs, ElementsAre(false, false, true, false, false, false, false, false, false));
  auto bad = SplitShellWords("echo 'open");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message(), ::testing::HasSubstr("unterminated ' quote"));
}

TEST(ShellCommandLines, JoinsContinuationsAndSkipsCommentsAndOtherBlocks) {
  auto lines = ShellCommandLines(
      "text\n"
      "```sh\n"
      "build/x run a.yaml   # first\n"
      "# a comment line\n"
      "\n"
      "build/x experiment e.yaml \\\n"
      "    --hosts 'local?slots=2'\n"
      "```\n"
      "```\n"
      "ninja -C build\n"
      "```\n"
      "```yaml\n"
      "name: x\n"
      "```\n");
  ASSERT_TRUE(lines) << lines.error().ToString();
  ASSERT_EQ(lines->size(), 2u);
  EXPECT_EQ((*lines)[0].line, 3);
  EXPECT_EQ((*lines)[0].Key(), "build/x run a.yaml");
  EXPECT_EQ((*lines)[1].line, 6);
  EXPECT_EQ((*lines)[1].Key(), "build/x experiment e.yaml --hosts local?slots=2");
}

}  // namespace
}  // namespace swarmbox::docs
