#pragma once
// gyrocal history show (docs/history.md): a unit's repeatability, as a table and as JSON.
#include <string>

#include <CLI/CLI.hpp>

#include "gyrocal/history/summary.hpp"

namespace gyrocal::cli {

/// Adds `show` to the `history` subcommand: `history show --unit SERIAL [--db FILE] [--config FILE]
/// [--json OUT] [--force]`.
void register_history_show(CLI::App& history);

/// The readable table of a unit's history: a line on the unit and its runs, then per channel (and for the
/// rig's machine errors) one line per quantity: runs, weighted mean ± σ, run-to-run std with its interval,
/// mean stated σ, their ratio, the F-test's p, trend per day ± σ with its p, the runs flagged.
std::string history_table(const history::HistorySummary& summary, const std::string& database);

}  // namespace gyrocal::cli
