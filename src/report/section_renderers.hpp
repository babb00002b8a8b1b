#pragma once
// The render functions of a result's sections and what they share, private to src/report (docs/report.md):
// one file per kind of section; sections.cpp, sensitivity_sections.cpp and montecarlo_sections.cpp hold the
// tables of the three pages (sections.hpp). Each render function draws its section of `result` into `out`
// (its plots through `page`) and throws gyrocal::Error on a malformed section (its page shows the sentence).
#include <optional>
#include <string>
#include <string_view>

#include "html_writing.hpp"
#include "page.hpp"

namespace gyrocal::report::section {

// --- what every page shares (section_common.cpp) ---

/// The unit of the coefficient `name` in the result's `coefficients`, or "".
std::string unit_of(const json& result, const std::string& name);

/// The unit of an estimate: the study's own `units` {name: unit}, else the result's coefficients'.
std::string estimate_unit(const json& s, const json& result, const std::string& name);

/// The truth of `name` in the result's `truth` {name: value}, if it is a number.
std::optional<double> truth_of(const json& result, const std::string& name);

/// The estimates a result names unidentifiable (`not_identifiable`, {name: reason}), each with its reason,
/// as a highlighted list; empty when there are none.
std::string not_identifiable_notes(const json* not_identifiable, std::string_view where);

/// True when the result holds `key`.
bool has(const json& result, std::string_view key);

/// True when the result is an accelerometer's (its `sensor` is "accelerometer").
bool is_accelerometer(const json& result);

/// `body` folded under a line that says what it holds (`summary`, escaped here): a <details> element, closed
/// on the screen; the page opens every fold to draw its plots, to measure its tables and to print.
std::string folded(std::string_view summary, const std::string& body);

/// The unit under test (`unit_under_test`: serial, model, operator, date, temperature, notes), the sensor,
/// the record and the gyrocal that calibrated; for an accelerometer's result without it, what would state it.
void unit_under_test(const json& result, Page&, std::string& out);

/// True when the result states its unit under test, or is an accelerometer's calibration.
bool has_unit_under_test(const json& r);

/// Where the result came from: the record, the configuration, the gyrocal that wrote it and what it is.
void provenance(const json& result, Page&, std::string& out);

/// True when the result holds one of the provenance section's keys.
bool has_provenance(const json& r);

// --- what was run (plan_sections.cpp) ---

void summary(const json& result, Page&, std::string& out);
void test_plan(const json& result, Page& page, std::string& out);
/// The g-levels, the planned duration and the test's sequence (`test_sequence`), with the measured span of
/// the dwells when the result has them.
void test_sequence(const json& result, Page&, std::string& out);

// --- the estimates (estimate_sections.cpp) ---

void coefficients(const json& result, Page& page, std::string& out);
void combinations(const json& result, Page&, std::string& out);
void alternatives(const json& result, Page&, std::string& out);
void comparison(const json& result, Page&, std::string& out);
void machine_errors(const json& result, Page&, std::string& out);

// --- the data (data_sections.cpp) ---

void data_quality(const json& result, Page&, std::string& out);
void positions(const json& result, Page& page, std::string& out);
/// An accelerometer's linearity: the residual of each reduced position against its input a_i (g), one series
/// per beta (`positions` joined with `position_inputs` by index).
void linearity(const json& result, Page& page, std::string& out);

// --- the studies beyond one calibration (sensitivity_sections.cpp, montecarlo_sections.cpp) ---

/// The result's `sensitivity` study: its heat maps and tables.
void sensitivity(const json& result, Page& page, std::string& out);

/// The result's `montecarlo` run: its distributions and variance budget.
void montecarlo(const json& result, Page& page, std::string& out);

}  // namespace gyrocal::report::section
