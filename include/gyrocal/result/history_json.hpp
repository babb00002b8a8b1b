#pragma once
// A unit's calibration history as `history show --json` writes it (docs/interface.md, "Calibration history
// (SQLite)"; docs/history.md): its runs, and per channel's coefficient and per machine error the runs' values
// and their repeatability.
#include <nlohmann/json.hpp>

#include "gyrocal/history/summary.hpp"

namespace gyrocal {

/// { "unit", "sensor",
///   "runs": [{ "id", "date", "record_sha256", "note", "date_source", "gyrocal_version", "flags" }],
///   "channels": { CHANNEL: { COEFFICIENT: ENTRY } }, "machine_errors": { ERROR: ENTRY } }
/// in the summary's orders (runs by date, then id; channels and coefficients in the runs' order; machine
/// errors by first appearance). ENTRY: { "unit", "runs": [{ "id", "date", "value", "std" }], "unidentified"
/// (run ids), "mean", "mean_std", "run_to_run_std", "run_to_run_std_low", "run_to_run_std_high",
/// "mean_stated_std", "std_ratio", "f_test_p", "trend_per_day", "trend_std", "trend_p", "limits" ([low,
/// high]), "flagged" (run ids), "ewma", "ewma_limits" ([[low, high], ...]), "ewma_flagged" (run ids) },
/// values in the entry's unit (trend_per_day per day); a statistic the runs do not give
/// (analysis/repeatability.hpp) is null, and so is any number that is not finite. A run's `flags` names each
/// quantity whose individuals chart or EWMA flagged that run: "CHANNEL/COEFFICIENT" or "machine/ERROR".
nlohmann::ordered_json history_to_json(const history::HistorySummary& summary);

}  // namespace gyrocal
