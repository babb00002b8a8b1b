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

bool has_summary(const json& r) {
  return has(r, "method") || has(r, "compensation") || has(r, "g_level") || has(r, "warnings") ||
         has(r, "misfit");
}

/// A list the accelerometer's page shows only when it holds something (a least-squares fit has no
/// alternatives; a full-rank one no combinations).
bool has_entries(const json& r, std::string_view key) {
  const json* v = find(r, key);
  return v != nullptr && !(v->is_array() && v->empty());
}

/// The table of the sections of a gyro's result report: it drives both the page and its navigation. The
/// result first (estimates, the fit's verdict), then the pictures and studies, then what was run and the
/// long tables (folded), then where the result came from.
const Section kResultSections[] = {
    {"unit", "unit", "Unit under test", unit_under_test,
     [](const json& r) { return has(r, "unit_under_test"); }},
    {"coefficients", "coefficients", "Drift coefficients", coefficients,
     [](const json& r) { return has(r, "coefficients"); }},
    {"machine_errors", "machine-errors", "Estimated machine errors", machine_errors,
     [](const json& r) { return has(r, "machine_errors"); }},
    {"summary", "summary", "Summary", summary, has_summary},
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
    {"test_sequence", "test", "The test: g-levels, sequence and duration", test_sequence,
     [](const json& r) { return has(r, "test_sequence"); }},
    {"plan", "plan", "Test plan", test_plan, [](const json& r) { return has(r, "plan"); }},
    {"data_quality", "data-quality", "Data quality", data_quality,
     [](const json& r) { return has(r, "data_quality"); }},
    {"provenance", "provenance", "Provenance", provenance, has_provenance},
};

/// The accelerometer's page (IEEE Std 836/1293 practice): the unit under test and its conditions, the
/// coefficients with their standard and expanded uncertainties, the machine errors (the radius in um) and
/// the fit's verdict; then the linearity plot and the residuals; then the g-levels and sequence; the plan's
/// grid and the dwells folded at the end. No gyro word: a gyro's sections that an accelerometer's result
/// leaves empty are not drawn.
const Section kAccelerometerSections[] = {
    {"unit", "unit", "Unit under test", unit_under_test, has_unit_under_test},
    {"coefficients", "coefficients", "Coefficients (IEEE Std 1293 model)", coefficients,
     [](const json& r) { return has(r, "coefficients"); }},
    {"machine_errors", "machine-errors", "Estimated machine errors", machine_errors,
     [](const json& r) { return has(r, "machine_errors"); }},
    {"summary", "summary", "Fit and warnings", summary, has_summary},
    {"combinations", "combinations", "Identifiable combinations", combinations,
     [](const json& r) { return has_entries(r, "combinations"); }},
    {"alternatives", "alternatives", "Alternative closed forms", alternatives,
     [](const json& r) { return has_entries(r, "alternatives"); }},
    {"linearity", "linearity", "Linearity: residual against input", linearity,
     [](const json& r) { return has(r, "positions") && has(r, "position_inputs"); }},
    {"positions", "positions", "Reduced positions", positions,
     [](const json& r) { return has(r, "positions"); }},
    {"comparison", "comparison", "Methods and compensations compared", comparison,
     [](const json& r) { return has(r, "comparison"); }},
    {"sensitivity", "sensitivity", "Sensitivity to machine errors", sensitivity,
     [](const json& r) { return has(r, "sensitivity"); }},
    {"montecarlo", "montecarlo", "Monte Carlo uncertainty", montecarlo,
     [](const json& r) { return has(r, "montecarlo"); }},
    {"test_sequence", "test", "The test: g-levels, sequence and duration", test_sequence,
     [](const json& r) { return has(r, "test_sequence"); }},
    {"plan", "plan", "Test plan", test_plan, [](const json& r) { return has(r, "plan"); }},
    {"data_quality", "data-quality", "Data quality", data_quality,
     [](const json& r) { return has(r, "data_quality"); }},
    {"provenance", "provenance", "Provenance", provenance, has_provenance},
};

}  // namespace

std::span<const Section> result_sections() {
  return kResultSections;
}

std::span<const Section> accelerometer_result_sections() {
  return kAccelerometerSections;
}

}  // namespace gyrocal::report
