#pragma once
// Reading one unit's history for `history show`, `report --history` and Python's gyrocal.history()
// (docs/history.md): the database opened read-only, the unit's runs, their summary; one refusal for all
// three.
#include <cstddef>
#include <filesystem>
#include <string>

#include "gyrocal/history/summary.hpp"

namespace gyrocal::history {

/// How many units the refusal of an unknown unit lists at most (then how many more there are).
inline constexpr std::size_t kUnitsListed = 50;

/// The summary (summarize()) of `unit`'s runs in the history database at `path`, opened read-only (Database's
/// kRead): nothing is written, and a missing file is refused naming it, never created. A unit with no run is
/// refused (gyrocal::Error) naming the database and the unit and listing the units it holds (the first
/// kUnitsListed of them, sorted), or saying that it holds none.
HistorySummary read_unit_history(const std::filesystem::path& path, const std::string& unit);

}  // namespace gyrocal::history
