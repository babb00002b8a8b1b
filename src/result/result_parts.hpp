#pragma once
// The pieces of a calibration's result JSON that a lone sensor's result (calibration_json.cpp) and an IMU's
// (imu_calibration_json.cpp) both write, keyed as docs/interface.md's "Result (JSON)". Internal to
// src/result.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gyrocal/identify/calibration.hpp"

namespace gyrocal {

/// {name: {value, std, unit, identifiable[, reason]}} in the table's order; value and std null where not
/// identifiable.
nlohmann::ordered_json coefficients_to_json(const std::vector<CoefficientEstimate>& estimates);
/// One entry per reduced position: index, beta_deg, gamma_deg, rate_rad_s, mean, std_err, unit (the sensor's:
/// deg/h, g), samples, outliers, residual; `channel` first when not empty (an IMU's); a lone gyro's also as
/// mean_deg_h, std_err_deg_h, residual_deg_h.
nlohmann::ordered_json positions_to_json(const std::vector<ReducedPosition>& positions,
                                         const std::vector<double>& residuals, SensorKind sensor,
                                         const std::string& channel);
/// {tested, p_value, weight_dof, std_scale}.
nlohmann::ordered_json misfit_to_json(const MisfitTest& misfit);
/// {rows_read, rows_used, outliers, gaps, encoder_glitch_rows, dwells, rejected}.
nlohmann::ordered_json data_quality_to_json(const DataQuality& quality);
/// One entry per estimated machine error: error, harmonic, value, std, unit, configured, identifiable,
/// [part], [reason], correlations.
nlohmann::ordered_json machine_errors_to_json(const std::vector<MachineErrorEstimate>& estimates);

}  // namespace gyrocal
