#include "markdown.hpp"

#include <cctype>
#include <map>
#include <regex>

namespace swarmbox::docs {
namespace {

std::vector<std::string_view> Lines(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) {
      if (start < text.size()) lines.push_back(text.substr(start));
      break;
    }
    lines.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return lines;
}

std::string_view TrimLeft(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  return s;
}

// "```sh" -> "sh"; nullopt-like empty optional when the line is no fence. Fences of ``` and ~~~.
bool IsFence(std::string_view line, std::string* info) {
  const std::string_view t = TrimLeft(line);
  if (t.substr(0, 3) != "```" && t.substr(0, 3) != "~~~") return false;
  std::string_view rest = t.substr(3);
  while (!rest.empty() && (rest.front() == '`' || rest.front() == '~')) rest.remove_prefix(1);
  rest = TrimLeft(rest);
  const std::size_t space = rest.find_first_of(" \t{");
  if (info != nullptr) *info = std::string(rest.substr(0, space));
  return true;
}

// The line with its code spans (`...`, ``...``) blanked, so links inside them are not links.
std::string WithoutCodeSpans(std::string_view line) {
  std::string out(line);
  std::size_t i = 0;
  while (i < out.size()) {
    if (out[i] != '`') {
      ++i;
      continue;
    }
    std::size_t ticks = 0;
    while (i + ticks < out.size() && out[i + ticks] == '`') ++ticks;
    const std::string delim(ticks, '`');
    const std::size_t close = out.find(delim, i + ticks);
    if (close == std::string::npos) break;  // an unmatched run is literal
    for (std::size_t k = i; k < close + ticks; ++k) out[k] = ' ';
    i = close + ticks;
  }
  return out;
}

// The target of an inline link starting at `open` (just after "]("): <...> or up to the
// whitespace or the ')' that closes it (balanced parentheses inside are kept).
std::string InlineTarget(const std::string& s, std::size_t open) {
  std::size_t i = open;
  while (i < s.size() && s[i] == ' ') ++i;
  if (i < s.size() && s[i] == '<') {
    const std::size_t close = s.find('>', i);
    return close == std::string::npos ? std::string() : s.substr(i + 1, close - i - 1);
  }
  int depth = 0;
  std::string target;
  for (; i < s.size(); ++i) {
    const char c = s[i];
    if (c == ' ' || c == '\t') break;
    if (c == '(') ++depth;
    if (c == ')') {
      if (depth == 0) break;
      --depth;
    }
    target += c;
  }
  return target;
}

}  // namespace

std::vector<MarkdownLink> MarkdownLinks(std::string_view text) {
  static const std::regex kHtml(R"re(\b(?:src|href)\s*=\s*"([^"]*)")re", std::regex::icase);
  static const std::regex kReference(R"re(^ {0,3}\[[^\]]+\]:\s*(?:<([^>]*)>|(\S+)))re");
  std::vector<MarkdownLink> links;
  bool in_fence = false;
  int n = 0;
  for (std::string_view raw : Lines(text)) {
    ++n;
    if (IsFence(raw, nullptr)) {
      in_fence = !in_fence;
      continue;
    }
    if (in_fence) continue;
    const std::string line = WithoutCodeSpans(raw);
    for (std::size_t at = line.find("]("); at != std::string::npos; at = line.find("](", at + 2)) {
      std::string target = InlineTarget(line, at + 2);
      if (!target.empty()) links.push_back({n, std::move(target)});
    }
    std::smatch m;
    if (std::regex_search(line, m, kReference)) links.push_back({n, m[1].matched ? m[1].str() : m[2].str()});
    for (auto it = std::sregex_iterator(line.begin(), line.end(), kHtml); it != std::sregex_iterator(); ++it) {
      links.push_back({n, (*it)[1].str()});
    }
  }
  return links;
}

std::string HeadingSlug(std::string_view heading) {
  std::string slug;
  for (const char c : heading) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isalnum(u) != 0 || c == '-' || c == '_') {
      slug += static_cast<char>(std::tolower(u));
    } else if (c == ' ') {
      slug += '-';
    } else if (u >= 0x80) {
      slug += c;  // non-ASCII letters stay as they are
    }
  }
  return slug;
}

std::set<std::string> HeadingAnchors(std::string_view text) {
  std::set<std::string> anchors;
  std::map<std::string, int> seen;
  bool in_fence = false;
  for (std::string_view raw : Lines(text)) {
    if (IsFence(raw, nullptr)) {
      in_fence = !in_fence;
      continue;
    }
    if (in_fence) continue;
    std::string_view line = TrimLeft(raw);
    std::size_t hashes = 0;
    while (hashes < line.size() && line[hashes] == '#') ++hashes;
    if (hashes == 0 || hashes > 6 || hashes >= line.size() || line[hashes] != ' ') continue;
    std::string_view title = line.substr(hashes + 1);
    while (!title.empty() && (title.back() == ' ' || title.back() == '#')) title.remove_suffix(1);
    title = TrimLeft(title);
    const std::string slug = HeadingSlug(title);
    const int count = seen[slug]++;
    anchors.insert(count == 0 ? slug : slug + "-" + std::to_string(count));
  }
  return anchors;
}

Result<std::vector<ShellWord>> SplitShellWords(std::string_view line) {
  std::vector<ShellWord> words;
  ShellWord word;
  bool in_word = false;
  auto finish = [&] {
    if (in_word) words.push_back(std::move(word));
    word = ShellWord{};
    in_word = false;
  };
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == ' ' || c == '\t') {
      finish();
    } else if (c == '#' && !in_word) {
      break;  // a comment
    } else if (c == '\'') {
      const std::size_t close = line.find('\'', i + 1);
      if (close == std::string_view::npos) {
        return Error(ErrorCode::kInvalidArgument, "unterminated ' quote", std::string(line));
      }
      word.text.append(line.substr(i + 1, close - i - 1));
      in_word = true;
      i = close;
    } else if (c == '"') {
      std::size_t k = i + 1;
      for (; k < line.size() && line[k] != '"'; ++k) {
        if (line[k] == '\\' && k + 1 < line.size() && std::string_view("\"\\$`").find(line[k + 1]) != std::string_view::npos) {
          ++k;
        }
        word.text += line[k];
      }
      if (k >= line.size()) {
        return Error(ErrorCode::kInvalidArgument, "unterminated \" quote", std::string(line));
      }
      in_word = true;
      i = k;
    } else if (c == '\\' && i + 1 < line.size()) {
      word.text += line[++i];
      in_word = true;
    } else {
      if (c == '*' || c == '?' || c == '[') word.glob = true;
      word.text += c;
      in_word = true;
    }
  }
  finish();
  return words;
}

std::string CommandLine::Key() const {
  std::string key;
  for (const ShellWord& w : words) {
    if (!key.empty()) key += ' ';
    key += w.text;
  }
  return key;
}

Result<std::vector<CommandLine>> ShellCommandLines(std::string_view text) {
  std::vector<CommandLine> commands;
  bool in_shell = false;
  bool in_other = false;
  std::string pending;
  int pending_line = 0;
  int n = 0;
  for (std::string_view raw : Lines(text)) {
    ++n;
    std::string info;
    if (!in_shell && !in_other && IsFence(raw, &info)) {
      (info == "sh" || info == "bash" || info == "shell" ? in_shell : in_other) = true;
      continue;
    }
    if ((in_shell || in_other) && IsFence(raw, nullptr)) {
      in_shell = in_other = false;
      pending.clear();
      continue;
    }
    if (!in_shell) continue;
    if (pending.empty()) pending_line = n;
    std::string_view part = raw;
    // A trailing backslash (outside a comment) continues the command on the next line.
    const bool continues = !part.empty() && part.back() == '\\' &&
                           TrimLeft(part).substr(0, 1) != "#";
    if (continues) part.remove_suffix(1);
    pending.append(part);
    if (continues) {
      pending += ' ';
      continue;
    }
    auto words = SplitShellWords(pending);
    if (!words) return words.error().Context("line " + std::to_string(pending_line));
    if (!words->empty()) commands.push_back({pending_line, std::move(*words)});
    pending.clear();
  }
  return commands;
}

}  // namespace swarmbox::docs
