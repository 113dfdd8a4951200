#include "experiment_check.hpp"

#include <algorithm>
#include <cctype>

namespace swarmbox::cli {

namespace {

constexpr std::string_view kSetPrefix = "--set ";

// "a.b:12:3" -> "a.b" (the ":line:col" a mark appends); text without it unchanged.
std::string_view StripLineColumn(std::string_view text) {
  for (int i = 0; i < 2; ++i) {
    const std::size_t colon = text.rfind(':');
    if (colon == std::string_view::npos || colon + 1 == text.size()) return text;
    for (std::size_t j = colon + 1; j < text.size(); ++j) {
      if (std::isdigit(static_cast<unsigned char>(text[j])) == 0) return text;
    }
    text = text.substr(0, colon);
  }
  return text;
}

const yaml::Node* LevelNode(const yaml::Node& factor, char code) {
  const yaml::Node* levels = factor.Find("levels");
  if (levels == nullptr || !levels->is_mapping()) return nullptr;
  for (const auto& [k, v] : levels->entries()) {
    if (k.is_scalar() && k.scalar() == std::string(1, code)) return &v;
  }
  return nullptr;
}

}  // namespace

bool LooksLikeExperiment(const yaml::Node& document) {
  return document.is_mapping() && document.Find("world") == nullptr &&
         (document.Find("factors") != nullptr || document.Find("base") != nullptr);
}

std::optional<std::string> OverrideKeyOf(const Error& error) {
  std::string_view where = error.where();
  if (where.substr(0, kSetPrefix.size()) != kSetPrefix) return std::nullopt;
  where.remove_prefix(kSetPrefix.size());
  const std::size_t eq = where.find('=');
  if (eq != std::string_view::npos) return std::string(where.substr(0, eq));
  const std::string_view key = StripLineColumn(where);
  if (key.empty()) return std::nullopt;
  return std::string(key);
}

std::optional<yaml::Mark> LocateOverride(const yaml::Node& doc, const experiment::PlannedTrial& trial,
                                         std::string_view key) {
  if (!doc.is_mapping()) return std::nullopt;
  const yaml::Node* factors = doc.Find("factors");
  if (factors != nullptr && factors->is_sequence()) {
    const auto& items = factors->items();
    for (std::size_t i = std::min(items.size(), trial.code.size()); i-- > 0;) {
      const yaml::Node* level = LevelNode(items[i], trial.code[i]);
      if (level == nullptr) continue;
      const yaml::Node* factor_key = items[i].Find("key");
      if (factor_key != nullptr) {
        if (factor_key->is_scalar() && factor_key->scalar() == key) return level->mark();
        continue;
      }
      if (const yaml::Node* v = level->is_mapping() ? level->Find(key) : nullptr) return v->mark();
    }
  }
  if (const yaml::Node* set = doc.Find("set"); set != nullptr && set->is_mapping()) {
    if (const yaml::Node* v = set->Find(key)) return v->mark();
  }
  if (key == "seed" || key == "name") {
    if (const yaml::Node* v = doc.Find(key)) return v->mark();
  }
  return std::nullopt;
}

Error LocateInExperiment(const Error& error, const yaml::Node& doc,
                         const experiment::PlannedTrial& trial) {
  const std::string which = "trial " + trial.id;
  const std::optional<std::string> key = OverrideKeyOf(error);
  if (key) {
    if (std::optional<yaml::Mark> mark = LocateOverride(doc, trial, *key)) {
      return Error(error.code(), error.message() + " (" + which + ", key " + *key + ")",
                   mark->ToString());
    }
  }
  return Error(error.code(), error.message() + " (" + which + ")", error.where());
}

}  // namespace swarmbox::cli
