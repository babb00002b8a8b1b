#pragma once
// The sections of a calibration result's report (docs/report.md), private to src/report.
#include <span>

#include "page.hpp"

namespace gyrocal::report {

/// The sections of a result's report in page order: summary, plan, data quality, coefficients, machine
/// errors, combinations, alternatives, comparison, positions, sensitivity, Monte Carlo. Each applies when its
/// key (or, for the summary, one of its keys) is in the result.
std::span<const Section> result_sections();

}  // namespace gyrocal::report
