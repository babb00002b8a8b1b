// Reading one unit's history (history/read.hpp).
#include "gyrocal/history/read.hpp"

#include <utility>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/history/database.hpp"

namespace gyrocal::history {

HistorySummary read_unit_history(const std::filesystem::path& path, const std::string& unit) {
  const Database db(path, Database::Mode::kRead);
  std::vector<Run> runs = db.runs(unit);
  if (runs.empty()) {
    const std::vector<std::string> units = db.units();
    if (units.empty())
      throw Error(fmt::format(
          "{} holds no runs of unit '{}': it holds no unit at all yet (`gyrocal history add` stores a run).",
          path.string(), unit));
    std::string list;
    for (std::size_t k = 0; k < units.size() && k < kUnitsListed; ++k)
      list += (k == 0 ? "" : ", ") + units[k];
    if (units.size() > kUnitsListed) list += fmt::format(" and {} more", units.size() - kUnitsListed);
    throw Error(fmt::format("{} holds no runs of unit '{}'; the {} it holds: {}.", path.string(), unit,
                            units.size() == 1 ? "unit" : fmt::format("{} units", units.size()), list));
  }
  return summarize(unit, std::move(runs));
}

}  // namespace gyrocal::history
