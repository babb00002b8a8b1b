#pragma once
// The result JSON of `gyrocal calibrate` (docs/contract.md, "Result (JSON)"), and the pieces the report
// reads.
#include <optional>

#include <nlohmann/json.hpp>

#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/model/gyro.hpp"
#include "gyrocal/plan/test_spec.hpp"

namespace gyrocal {

/// coefficients {name: {value, std, unit, identifiable}} (value and std null when not identifiable),
/// combinations, positions (with residual_deg_h for least squares), alternatives, method, compensation,
/// g_level, warnings; and rank, condition_number, chi2, dof, unidentifiable. An ordered_json: the keys keep
/// the order they are written in, so the coefficients come in the contract's order dF dI dO dS dII dOO dSS
/// dIO dIS dOS (then the rate errors), not alphabetically (docs/contract.md, "Result (JSON)").
nlohmann::ordered_json calibration_to_json(const CalibrationResult& result);

/// {name: value} of the ten coefficients, in the contract's order.
nlohmann::ordered_json coefficients_to_json(const DriftCoefficients& coefficients);

/// The test plan: sample_rate_hz, revolutions, settle_s, beta_deg, gamma_deg, rates_rad_s, positions.
nlohmann::json plan_to_json(const TestSpec& plan);

}  // namespace gyrocal
