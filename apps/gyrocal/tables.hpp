#pragma once
// Text tables of results for the terminal. Formatting only.
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/analysis/sensitivity_imu.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/imu_calibration.hpp"
#include "gyrocal/model/gyro.hpp"
#include "gyrocal/sensor/sensor_model.hpp"

namespace gyrocal::cli {

/// "value ± std" with the digits the uncertainty justifies: the std to two significant digits and the value
/// to the same last digit (0.0700 ± 0.0018; scientific for large or tiny magnitudes); the value alone to 6
/// significant digits when the std is zero or unknown.
std::string format_value_std(double value, double std_dev);

/// How a unit is printed for people: a length in m (and m/(rad/s)^2) as um (um/(rad/s)^2), factor 1e6; any
/// other unit as it is, factor 1. The JSON keeps the contract's SI units.
struct PrintedUnit {
  double factor = 1.0;  ///< the value in `unit` is the value in the SI unit times this
  std::string unit;
};
PrintedUnit printed_unit(std::string_view unit);

/// Coefficients (value ± std, unit), combinations, alternatives, warnings of one result.
std::string result_table(const CalibrationResult& result);
/// An IMU's calibration as text (imu_table.cpp): each channel's coefficients and misfit, the shared errors.
std::string imu_result_table(const ImuCalibrationResult& result);

/// An IMU's error study as text (imu_table.cpp): per machine error, the estimates it shifts beyond the
/// threshold, each as its shift in its unit and in its predicted noise std.
std::string imu_sensitivity_table(const ImuSensitivityResult& result);

/// Several results side by side, with the truth in the first column when given.
std::string comparison_table(const std::vector<std::string>& labels,
                             const std::vector<CalibrationResult>& results, const DriftCoefficients* truth);

/// A sensor's coefficients (a table other than the gyro's: an accelerometer's K0 .. delta_o) for several
/// results side by side, the truth (in the table's units and order) in the first column.
std::string sensor_comparison_table(const std::vector<std::string>& labels,
                                    const std::vector<CalibrationResult>& results,
                                    std::span<const SensorParameter> parameters,
                                    std::span<const double> truth);

/// The Allan deviation with its bounds and dominant term, then the fitted terms with their uncertainties.
std::string noise_table(const RecordNoise& result);
/// The fitted terms of one characterised output, one line each in its sensor's keys and units (and an
/// accelerometer's quantization_ug), then the fit's weighted misfit: noise_table's last part.
std::string noise_terms_lines(const RecordNoise& result);
/// The text table of `gyrocal noise` for an IMU: the record's rows and rate, then per channel (its sensor,
/// column and samples) its fitted terms as noise_terms_lines writes them.
std::string imu_noise_table(const ImuRecordNoise& result);

}  // namespace gyrocal::cli
