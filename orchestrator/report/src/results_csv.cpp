#include "swarmbox/report/results_csv.hpp"

#include <cmath>
#include <cstdio>

namespace swarmbox::report {

std::string CsvField(std::string_view text) {
  if (text.find_first_of(",\"\n\r") == std::string_view::npos) return std::string(text);
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string CsvNumber(double value) {
  if (!std::isfinite(value)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", value);
  std::string s = buf;
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  if (s == "-0") s = "0";
  return s;
}

std::string ResultsCsv(const std::vector<std::string>& factors,
                       const std::vector<TrialRecord>& records) {
  std::string out = "trial_id,code";
  for (const std::string& f : factors) out += "," + CsvField(f);
  out += ",repetition,seed,host,outcome,reason,wall_s,sim_s";
  for (const std::string& m : MetricNames()) out += "," + m;
  for (const std::string& c : ProvenanceColumns()) out += "," + c;
  out += "\n";
  for (const TrialRecord& r : records) {
    out += CsvField(r.meta.id) + "," + CsvField(r.meta.code);
    for (std::size_t i = 0; i < factors.size(); ++i) {
      out += "," + (i < r.meta.levels.size() ? CsvField(r.meta.levels[i]) : std::string());
    }
    out += "," + std::to_string(r.meta.repetition) + "," + std::to_string(r.meta.seed) + "," +
           CsvField(r.host) + "," + CsvField(r.outcome) + "," + CsvField(r.reason) + "," +
           (r.wall_s ? CsvNumber(*r.wall_s) : "") + "," + (r.sim_s ? CsvNumber(*r.sim_s) : "");
    for (const std::string& m : MetricNames()) {
      auto it = r.metrics.find(m);
      out += ",";
      if (it != r.metrics.end() && it->second) out += CsvNumber(*it->second);
    }
    for (const std::string& cell : ProvenanceCells(r.provenance)) out += "," + CsvField(cell);
    out += "\n";
  }
  return out;
}

}  // namespace swarmbox::report
