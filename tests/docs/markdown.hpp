// What the docs tests read in Markdown, as pure functions over a file's text (no I/O): the links a
// reader can follow, the anchors a file's headings give, and the command lines of its shell code
// blocks split into words the way a POSIX shell would (quotes, backslash continuation, comments),
// so the README's commands run from argv arrays, never through a shell.
//
//   for (const MarkdownLink& l : MarkdownLinks(text)) ...      // l.line, l.target ("docs/x.md#y")
//   HeadingSlug("Status (2026-11-21)") == "status-2026-11-21"  // GitHub's anchor for a heading
//   for (const CommandLine& c : ShellCommandLines(text)) ...   // c.line, c.words ({"swarmbox", ...})
#pragma once

#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::docs {

// A link as written: inline `[text](target "title")` and `![alt](target)`, reference definitions
// `[id]: target`, and HTML `src="..."`/`href="..."`. Outside fenced code blocks and code spans.
struct MarkdownLink {
  int line = 0;        // 1-based
  std::string target;  // as written, without the angle brackets or the title
};
std::vector<MarkdownLink> MarkdownLinks(std::string_view text);

// GitHub's anchor for a heading's text: lower case, punctuation other than '-' and '_' dropped,
// spaces to '-'.
std::string HeadingSlug(std::string_view heading);
// Every anchor the ATX headings (`# ...`) of `text` give, duplicates numbered as GitHub does
// ("x", "x-1", ...). Outside fenced code blocks.
std::set<std::string> HeadingAnchors(std::string_view text);

// One shell word; `glob` when it holds an unquoted *, ? or [ (the shell would expand it).
struct ShellWord {
  std::string text;
  bool glob = false;
};
// Splits one command line as a POSIX shell would, without expanding anything: single quotes,
// double quotes (backslash escapes \" \\ \$ \`), backslash outside quotes, an unquoted '#' at the
// start of a word begins a comment. kInvalidArgument on an unterminated quote.
Result<std::vector<ShellWord>> SplitShellWords(std::string_view line);

// A command line of a ```sh (or bash, shell) code block: lines ending in '\' joined to the next,
// comment-only and blank lines left out.
struct CommandLine {
  int line = 0;                  // 1-based, where the command starts
  std::vector<ShellWord> words;  // never empty
  // The words joined by single spaces (quotes removed): how tests name a line.
  std::string Key() const;
};
Result<std::vector<CommandLine>> ShellCommandLines(std::string_view text);

}  // namespace swarmbox::docs
