// The sections of a calibration result's report (docs/report.md): the table (result_sections) that says
// which are drawn, in which order, under which heading. Each section's render function is in the file of its
// kind (section_renderers.hpp).
#include "section_renderers.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <unordered_map>
#include <utility>

#include <fmt/format.h>

#include "charts.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/report/html_report.hpp"
#include "html_writing.hpp"

namespace gyrocal::report {
namespace {

using namespace section;

/// The table of the sections of a result's report: it drives both the page and its navigation.
const Section kResultSections[] = {
    {"provenance", "provenance", "Provenance", provenance, has_provenance},
    {"summary", "summary", "Summary", summary,
     [](const json& r) {
       return has(r, "method") || has(r, "compensation") || has(r, "g_level") || has(r, "warnings");
     }},
    {"plan", "plan", "Test plan", test_plan, [](const json& r) { return has(r, "plan"); }},
    {"data_quality", "data-quality", "Data quality", data_quality,
     [](const json& r) { return has(r, "data_quality"); }},
    {"coefficients", "coefficients", "Drift coefficients", coefficients,
     [](const json& r) { return has(r, "coefficients"); }},
    {"machine_errors", "machine-errors", "Estimated machine errors", machine_errors,
     [](const json& r) { return has(r, "machine_errors"); }},
    {"combinations", "combinations", "Identifiable combinations", combinations,
     [](const json& r) { return has(r, "combinations"); }},
    {"alternatives", "alternatives", "Alternative closed forms", alternatives,
     [](const json& r) { return has(r, "alternatives"); }},
    {"comparison", "comparison", "Methods and compensations compared", comparison,
     [](const json& r) { return has(r, "comparison"); }},
    {"positions", "positions", "Reduced positions", positions,
     [](const json& r) { return has(r, "positions"); }},
    {"sensitivity", "sensitivity", "Sensitivity to machine errors", sensitivity,
     [](const json& r) { return has(r, "sensitivity"); }},
    {"montecarlo", "montecarlo", "Monte Carlo uncertainty", montecarlo,
     [](const json& r) { return has(r, "montecarlo"); }},
};

}  // namespace

std::span<const Section> result_sections() {
  return kResultSections;
}

}  // namespace gyrocal::report
