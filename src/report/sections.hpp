#pragma once
// The sections of a calibration result's report (docs/report.md), private to src/report.
#include <span>

#include "page.hpp"

namespace gyrocal::report {

/// The sections of a gyro's calibration (or plan) result's report in page order, the result first: unit
/// under test, coefficients, machine errors, summary (the misfit verdict, warnings), combinations,
/// alternatives, comparison, positions, sensitivity, Monte Carlo, the test's g-levels and sequence, the plan
/// and data quality (their long tables folded), provenance. Each applies when its key (or, for the summary,
/// one of its keys) is in the result.
std::span<const Section> result_sections();

/// The same page for an accelerometer's result (its `sensor` is "accelerometer"; IEEE Std 836/1293
/// practice): its own headings, the unit under test always, the linearity plot after the fit, the
/// combinations and alternatives only when they hold something.
std::span<const Section> accelerometer_result_sections();

/// The page of a sensitivity study (sensitivity_to_json): provenance, the study's settings and noise
/// standard uncertainties, the closed forms' heat maps, least squares' affected estimates.
std::span<const Section> sensitivity_sections();

/// The page of a Monte Carlo run (montecarlo_to_json): provenance, the run's settings and error sources,
/// the distributions (histograms) and the variance budget.
std::span<const Section> montecarlo_sections();

/// The page of a noise characterisation (noise_to_json; noise_report.cpp).
std::span<const Section> noise_sections();

}  // namespace gyrocal::report
