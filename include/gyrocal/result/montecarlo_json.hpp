#pragma once
// The JSON of `gyrocal montecarlo` (read by the report: tests/data/report_sample.json's "montecarlo").
#include <nlohmann/json.hpp>

#include "gyrocal/analysis/montecarlo.hpp"

namespace gyrocal {

/// { "trials", "mode" ("fast" | "samples"), "seed", "method", "compensation",
///   "coefficients": {name: {mean, std, unit, truth, predicted_mean, predicted_std,
///                           histogram: {edges, counts}}},
///   "budget": {name: {source: share}},
///   "sources": [{name, std, unit}] }
/// mean and std are those of the error (estimate - truth), in the estimate's unit; the budget's sources
/// are "noise" and each [uncertainty] entry (error key, "_h<n>" for a harmonic), its shares sum to 1.
nlohmann::json montecarlo_to_json(const MonteCarloResult& result);

}  // namespace gyrocal
