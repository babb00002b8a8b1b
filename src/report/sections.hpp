#pragma once
// The sections of a calibration result's report (docs/report.md), private to src/report.
#include <span>

#include "page.hpp"

namespace gyrocal::report {

/// The sections of a calibration (or plan) result's report in page order: provenance, summary, plan, data
/// quality, coefficients, machine errors, combinations, alternatives, comparison, positions, sensitivity,
/// Monte Carlo. Each applies when its key (or, for the summary, one of its keys) is in the result.
std::span<const Section> result_sections();

/// The page of a sensitivity study (sensitivity_to_json): provenance, the study's settings and noise
/// standard uncertainties, the closed forms' heat maps, least squares' affected estimates.
std::span<const Section> sensitivity_sections();

/// The page of a Monte Carlo run (montecarlo_to_json): provenance, the run's settings and error sources,
/// the distributions (histograms) and the variance budget.
std::span<const Section> montecarlo_sections();

/// The page of a noise characterisation (noise_to_json; noise_report.cpp).
std::span<const Section> noise_sections();

}  // namespace gyrocal::report
