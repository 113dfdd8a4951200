#include "swarmbox/experiment/experiment_spec.hpp"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <set>

namespace swarmbox::experiment {

namespace {

using yaml::Node;
namespace fs = std::filesystem;

constexpr std::size_t kMaxTrialName = 40;  // the trial loader's limit (folders, containers)

Error At(const Node& node, std::string message) {
  return Error(ErrorCode::kInvalidArgument, std::move(message), node.Where());
}

bool IsName(std::string_view s) {
  if (s.empty()) return false;
  auto alnum = [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'); };
  if (!alnum(s[0])) return false;
  return std::all_of(s.begin(), s.end(),
                     [&](char c) { return alnum(c) || c == '-' || c == '_' || c == '.'; });
}

// "key=value" with the value as one-line JSON (valid YAML, read back by dsl::ApplyOverride).
std::string Assignment(std::string_view key, const Node& value) {
  return std::string(key) + "=" + yaml::EmitJson(value);
}

Result<std::vector<std::string>> OverridesOf(const Node& mapping, std::string_view what) {
  if (!mapping.is_mapping()) {
    return At(mapping, std::string(what) + " must be a mapping of trial keys to values");
  }
  std::vector<std::string> out;
  for (const auto& [k, v] : mapping.entries()) {
    if (!k.is_scalar() || k.scalar().empty()) return At(k, "expected a trial key (a.b.c)");
    out.push_back(Assignment(k.scalar(), v));
  }
  return out;
}

// 'keys': not with 'key', at least one, none empty.
Status CheckFactorKeys(const Node& node, const Factor& f) {
  const Node* keys = node.Find("keys");
  if (keys == nullptr) return Ok{};
  if (node.Find("key") != nullptr) {
    return At(*keys, "give 'key' (one trial key per level) or 'keys' (several), not both");
  }
  if (f.keys.empty()) return At(*keys, "'keys' must list at least one trial key");
  for (std::size_t i = 0; i < f.keys.size(); ++i) {
    if (f.keys[i].empty()) return At(keys->items()[i], "expected a trial key (a.b.c)");
  }
  return Ok{};
}

// A level's overrides and label from its value: one key's value, a list with one value per key,
// or (without key and keys) a mapping of overrides.
Status DecodeLevelValue(const Factor& f, const Node& k, const Node& v, Level* level) {
  if (!f.key.empty()) {
    level->overrides.push_back(Assignment(f.key, v));
    level->label = v.is_scalar() ? v.scalar() : std::string(1, level->code);
  } else if (!f.keys.empty()) {
    if (!v.is_sequence() || v.items().size() != f.keys.size()) {
      return At(v, "level '" + k.scalar() + "' must be a list of " + std::to_string(f.keys.size()) +
                       " values, one per key of 'keys' in that order");
    }
    for (std::size_t i = 0; i < f.keys.size(); ++i) level->overrides.push_back(Assignment(f.keys[i], v.items()[i]));
    const Node& first = v.items().front();
    level->label = first.is_scalar() ? first.scalar() : std::string(1, level->code);
  } else {
    auto o = OverridesOf(v, "a level of a factor without 'key'");
    if (!o) return o.error();
    level->overrides = std::move(*o);
    level->label = std::string(1, level->code);
  }
  return Ok{};
}

// 'levels': one-letter codes, each once, sorted by code.
Status DecodeLevels(const Node& levels, Factor* f) {
  if (!levels.is_mapping() || levels.entries().empty()) {
    return At(levels, "'levels' must be a non-empty mapping of one-letter codes to values");
  }
  for (const auto& [k, v] : levels.entries()) {
    if (!k.is_scalar() || k.scalar().size() != 1 || k.scalar()[0] < 'a' || k.scalar()[0] > 'z') {
      return At(k, "a level code is one letter a-z, got '" + k.scalar() + "'");
    }
    Level level;
    level.code = k.scalar()[0];
    if (f->FindLevel(level.code) != nullptr) {
      return At(k, "level '" + k.scalar() + "' is given twice in factor " + f->name);
    }
    SWARMBOX_TRY(DecodeLevelValue(*f, k, v, &level));
    f->levels.push_back(std::move(level));
  }
  std::sort(f->levels.begin(), f->levels.end(),
            [](const Level& a, const Level& b) { return a.code < b.code; });
  return Ok{};
}

// 'labels': names for known level codes.
Status DecodeLabels(const Node& labels, Factor* f) {
  if (!labels.is_mapping()) return At(labels, "'labels' must map level codes to names");
  for (const auto& [k, v] : labels.entries()) {
    auto level = std::find_if(f->levels.begin(), f->levels.end(), [&](const Level& l) {
      return k.is_scalar() && k.scalar().size() == 1 && l.code == k.scalar()[0];
    });
    if (level == f->levels.end()) return At(k, "label for an unknown level '" + k.scalar() + "'");
    if (!v.is_scalar()) return At(v, "a label is a plain name");
    level->label = v.scalar();
  }
  return Ok{};
}

Result<Factor> ParseFactor(const Node& node) {
  Factor f;
  if (!node.is_mapping()) return At(node, "a factor is a mapping {name, key or keys, levels, labels}");
  yaml::MapReader r(node, "factor");
  r.Required("name", &f.name).Optional("key", &f.key).Optional("keys", &f.keys);
  const Node* levels = r.Child("levels", /*required=*/true);
  const Node* labels = r.Child("labels");
  SWARMBOX_TRY(r.Finish());
  SWARMBOX_TRY(CheckFactorKeys(node, f));
  if (!IsName(f.name) || f.name.find('.') != std::string::npos) {
    return At(*node.Find("name"), "factor name '" + f.name +
                                      "' must be a-z, 0-9, '-', '_', starting with a letter or digit");
  }
  SWARMBOX_TRY(DecodeLevels(*levels, &f));
  if (labels != nullptr) SWARMBOX_TRY(DecodeLabels(*labels, &f));
  return f;
}

std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30U)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27U)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31U);
}

}  // namespace

const Level* Factor::FindLevel(char code) const {
  for (const Level& l : levels) {
    if (l.code == code) return &l;
  }
  return nullptr;
}

namespace {

// 'factors': a non-empty list of distinct {name, key, levels}.
Status DecodeFactors(const Node& factors, ExperimentSpec* spec) {
  if (!factors.is_sequence() || factors.items().empty()) {
    return At(factors, "'factors' must be a non-empty list of {name, key, levels}");
  }
  std::set<std::string> names;
  for (const Node& item : factors.items()) {
    auto f = ParseFactor(item);
    if (!f) return f.error();
    if (!names.insert(f->name).second) {
      return At(item, "factor '" + f->name + "' is given twice");
    }
    spec->factors.push_back(std::move(*f));
  }
  return Ok{};
}

// repetitions, seed and seeds.
Status DecodeSeeding(const Node& doc, std::optional<std::int64_t> seed, const std::string& seeds, ExperimentSpec* spec) {
  if (spec->repetitions < 1) {
    return At(*doc.Find("repetitions"), "'repetitions' must be at least 1");
  }
  if (seed) {
    if (*seed < 0) return At(*doc.Find("seed"), "'seed' must not be negative");
    spec->seed = static_cast<std::uint64_t>(*seed);
    spec->seed_given = true;
  }
  if (seeds == "paired") {
    spec->seeds = SeedMode::kPaired;
  } else if (seeds == "independent") {
    spec->seeds = SeedMode::kIndependent;
  } else {
    return At(*doc.Find("seeds"), "'seeds' is paired or independent, got '" + seeds + "'");
  }
  return Ok{};
}

// The longest trial id must still be a valid trial name; codes and filter patterns fit the factors.
Status CheckIdsCodesAndFilter(const Node& doc, const Node* filter, const ExperimentSpec& spec) {
  const std::string longest =
      TrialId(spec.name, std::string(spec.factors.size(), 'a'), spec.repetitions);
  if (longest.size() > kMaxTrialName) {
    return At(*doc.Find("name"), "trial ids like '" + longest + "' exceed " +
                                     std::to_string(kMaxTrialName) +
                                     " characters (they name folders and containers): use a "
                                     "shorter experiment name");
  }
  for (const std::string& code : spec.codes) {
    if (auto s = CheckCode(spec.factors, code); !s) {
      return At(*doc.Find("codes"), s.error().message());
    }
  }
  for (const std::string& pattern : spec.filter) {
    if (pattern.size() != spec.factors.size()) {
      return At(*filter, "filter pattern '" + pattern + "' must have one letter or '?' per factor (" +
                             std::to_string(spec.factors.size()) + ")");
    }
  }
  return Ok{};
}

}  // namespace

Result<ExperimentSpec> ParseExperiment(const yaml::Node& doc, std::string_view file) {
  ExperimentSpec spec;
  spec.file = std::string(file);
  if (!doc.is_mapping()) return At(doc, "an experiment is a mapping {name, base, factors, ...}");
  yaml::MapReader r(doc, "experiment");
  std::string seeds = "paired";
  std::optional<std::int64_t> seed;
  r.Required("name", &spec.name)
      .Required("base", &spec.base_trial)
      .Optional("codes", &spec.codes)
      .Optional("repetitions", &spec.repetitions)
      .Optional("seed", &seed)
      .Optional("seeds", &seeds)
      .Optional("hosts", &spec.hosts);
  const Node* set = r.Child("set");
  const Node* factors = r.Child("factors", /*required=*/true);
  const Node* filter = r.Child("filter");
  SWARMBOX_TRY(r.Finish());
  if (!IsName(spec.name)) {
    return At(*doc.Find("name"), "experiment name '" + spec.name +
                                     "' must be a-z, 0-9, '-', '_', '.', starting with a letter "
                                     "or digit");
  }
  if (set != nullptr) {
    auto o = OverridesOf(*set, "'set'");
    if (!o) return o.error();
    spec.set = std::move(*o);
  }
  SWARMBOX_TRY(DecodeFactors(*factors, &spec));
  if (filter != nullptr) {
    if (filter->is_scalar()) {
      spec.filter.push_back(filter->scalar());
    } else if (auto s = yaml::Decode(*filter, &spec.filter); !s) {
      return s.error();
    }
  }
  SWARMBOX_TRY(DecodeSeeding(doc, seed, seeds, &spec));
  SWARMBOX_TRY(CheckIdsCodesAndFilter(doc, filter, spec));
  return spec;
}

Result<ExperimentSpec> LoadExperiment(const std::string& path) {
  auto doc = yaml::ParseFile(path);
  if (!doc) return doc.error();
  auto spec = ParseExperiment(*doc, path);
  if (!spec) return spec.error();
  fs::path base(spec->base_trial);
  if (base.is_relative()) base = fs::path(path).parent_path() / base;
  spec->base_trial = base.lexically_normal().string();
  auto trial = yaml::ParseFile(spec->base_trial);
  if (!trial) {
    return Error(ErrorCode::kInvalidArgument,
                 "base trial: " + trial.error().ToString(), doc->Find("base")->Where());
  }
  if (!spec->seed_given) {
    std::int64_t seed = 0;
    if (const Node* s = trial->is_mapping() ? trial->Find("seed") : nullptr) {
      if (auto v = s->AsInt(); v && *v >= 0) seed = *v;
    }
    spec->seed = static_cast<std::uint64_t>(seed);
  }
  return spec;
}

std::vector<std::string> FactorialCodes(const std::vector<Factor>& factors) {
  std::vector<std::string> codes{""};
  for (const Factor& f : factors) {
    std::vector<std::string> next;
    for (const std::string& prefix : codes) {
      for (const Level& l : f.levels) next.push_back(prefix + l.code);
    }
    codes = std::move(next);
  }
  return codes;
}

bool CodeMatches(std::string_view code, std::string_view pattern) {
  if (code.size() != pattern.size()) return false;
  for (std::size_t i = 0; i < code.size(); ++i) {
    if (pattern[i] != '?' && pattern[i] != '*' && pattern[i] != code[i]) return false;
  }
  return true;
}

std::uint64_t DeriveSeed(std::uint64_t base, SeedMode mode, std::string_view code, int rep) {
  std::uint64_t x = SplitMix64(base ^ SplitMix64(static_cast<std::uint64_t>(rep)));
  if (mode == SeedMode::kIndependent) {
    for (char c : code) x = SplitMix64(x ^ static_cast<unsigned char>(c));
  }
  return x & 0x7fffffffULL;
}

Status CheckCode(const std::vector<Factor>& factors, std::string_view code) {
  if (code.size() != factors.size()) {
    return Error(ErrorCode::kInvalidArgument,
                 "code '" + std::string(code) + "' must have one letter per factor (" +
                     std::to_string(factors.size()) + ")");
  }
  for (std::size_t i = 0; i < code.size(); ++i) {
    if (factors[i].FindLevel(code[i]) == nullptr) {
      std::string known;
      for (const Level& l : factors[i].levels) known += l.code;
      return Error(ErrorCode::kInvalidArgument, "code '" + std::string(code) + "': factor " +
                                                    factors[i].name + " has no level '" +
                                                    std::string(1, code[i]) + "' (levels: " +
                                                    known + ")");
    }
  }
  return Ok{};
}

std::string TrialId(std::string_view name, std::string_view code, int rep) {
  return std::string(name) + "-" + std::string(code) + "-r" + std::to_string(rep);
}

namespace {

// The codes (each valid, none twice) and filter patterns (one letter or '?' per factor) checked.
Status CheckCodesAndFilter(const ExperimentSpec& spec, const std::vector<std::string>& codes) {
  std::set<std::string> seen;
  for (const std::string& code : codes) {
    SWARMBOX_TRY(CheckCode(spec.factors, code));
    if (!seen.insert(code).second) {
      return Error(ErrorCode::kInvalidArgument, "code '" + code + "' is listed twice",
                   spec.file);
    }
  }
  for (const std::string& pattern : spec.filter) {
    if (pattern.size() != spec.factors.size()) {
      return Error(ErrorCode::kInvalidArgument,
                   "filter pattern '" + pattern + "' must have one letter or '?' per factor",
                   spec.file);
    }
  }
  return Ok{};
}

// Repetition `rep` of the checked `code`: its id, seed, levels and overrides (the experiment's
// `set:`, each level's, then the seed and the name).
PlannedTrial PlannedTrialOf(const ExperimentSpec& spec, const std::string& code, int rep) {
  PlannedTrial t;
  t.code = code;
  t.repetition = rep;
  t.id = TrialId(spec.name, code, rep);
  t.seed = DeriveSeed(spec.seed, spec.seeds, code, rep);
  t.overrides = spec.set;
  for (std::size_t i = 0; i < code.size(); ++i) {
    const Level* level = spec.factors[i].FindLevel(code[i]);
    t.levels.push_back(level->label);
    t.overrides.insert(t.overrides.end(), level->overrides.begin(), level->overrides.end());
  }
  t.overrides.push_back("seed=" + std::to_string(t.seed));
  t.overrides.push_back("name=" + t.id);
  return t;
}

}  // namespace

Result<std::vector<PlannedTrial>> ExpandTrials(const ExperimentSpec& spec) {
  std::vector<std::string> codes = spec.codes.empty() ? FactorialCodes(spec.factors) : spec.codes;
  SWARMBOX_TRY(CheckCodesAndFilter(spec, codes));
  std::vector<PlannedTrial> trials;
  for (const std::string& code : codes) {
    const bool keep = spec.filter.empty() ||
                      std::any_of(spec.filter.begin(), spec.filter.end(),
                                  [&](const std::string& p) { return CodeMatches(code, p); });
    if (!keep) continue;
    for (int rep = 1; rep <= spec.repetitions; ++rep) trials.push_back(PlannedTrialOf(spec, code, rep));
  }
  if (trials.empty()) {
    return Error(ErrorCode::kInvalidArgument, "the filter leaves no trial to run", spec.file);
  }
  return trials;
}

}  // namespace swarmbox::experiment
