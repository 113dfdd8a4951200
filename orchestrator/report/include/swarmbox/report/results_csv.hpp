// results.csv (ARCHITECTURE.md "Per-trial output", contract): one row per trial,
//   trial_id,code,<factors...>,repetition,seed,host,outcome,reason,wall_s,sim_s,<metrics...>,
//   <provenance...>
// (metrics: MetricNames(), trial_metrics.hpp; provenance: ProvenanceColumns(), provenance.hpp)
// RFC 4180 quoting (fields with a comma, quote or newline are quoted, quotes doubled); a metric a
// trial does not have is an empty cell. Pure.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/report/trial_record.hpp"

namespace swarmbox::report {

std::string CsvField(std::string_view text);
// A number for a cell: up to 6 significant decimals, no trailing zeros ("12.5", "3", "0.05").
std::string CsvNumber(double value);
std::string ResultsCsv(const std::vector<std::string>& factors,
                       const std::vector<TrialRecord>& records);

}  // namespace swarmbox::report
