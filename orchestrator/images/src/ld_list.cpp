#include "swarmbox/images/ld_list.hpp"

namespace swarmbox::images {
namespace {

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// Drops a trailing " (0x...)" load address.
std::string_view DropAddress(std::string_view s) {
  const std::size_t paren = s.rfind(" (0x");
  if (paren != std::string_view::npos && !s.empty() && s.back() == ')') s = s.substr(0, paren);
  return Trim(s);
}

}  // namespace

Result<std::vector<LdListEntry>> ParseLdList(std::string_view output) {
  std::vector<LdListEntry> entries;
  while (!output.empty()) {
    const std::size_t nl = output.find('\n');
    std::string_view line = Trim(output.substr(0, nl));
    output.remove_prefix(nl == std::string_view::npos ? output.size() : nl + 1);
    if (line.empty()) continue;
    const std::size_t arrow = line.find(" => ");
    if (arrow != std::string_view::npos) {
      LdListEntry e;
      e.name = std::string(Trim(line.substr(0, arrow)));
      std::string_view target = DropAddress(line.substr(arrow + 4));
      if (target == "not found") {
        entries.push_back(std::move(e));
        continue;
      }
      if (target.empty() || target.front() != '/') {
        return Error(ErrorCode::kProtocol, "unexpected loader output line: '" + std::string(line) + "'");
      }
      e.path = std::string(target);
      entries.push_back(std::move(e));
      continue;
    }
    std::string_view name = DropAddress(line);
    if (!name.empty() && name.front() == '/') {
      entries.push_back(LdListEntry{std::string(name), std::string(name)});
    } else if (name.find(' ') == std::string_view::npos && name.find(".so") != std::string_view::npos) {
      continue;  // linux-vdso.so.1 / linux-gate.so.1: provided by the kernel
    } else {
      return Error(ErrorCode::kProtocol, "unexpected loader output line: '" + std::string(line) + "'");
    }
  }
  return entries;
}

}  // namespace swarmbox::images
