#pragma once
// The error study of a whole IMU (docs/imu.md, "Sensitivity of an IMU"): each machine error alone, not told
// to the calibration, and the shift it causes in every channel's coefficients and in the shared errors the
// calibration estimates, exact (noise-free planned outputs through the joint solve), as the lone sensor's
// study (analysis/sensitivity.hpp) does for one sensor.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "gyrocal/analysis/sensitivity.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/calibration.hpp"

namespace gyrocal {

/// One machine error's effect on an IMU's calibration.
struct ImuSensitivityRow {
  MachineErrorTerm term;
  double value = 0.0;    ///< the magnitude studied, in term.unit
  bool typical = false;  ///< the configuration has zero and the typical magnitude was studied
  /// Estimate name ("gx.dI", "ax.K1", an estimated error's label "radius_error") -> its shift, estimate with
  /// the error less estimate without it, in the estimate's unit (an estimated error's: against its own
  /// value, so the part of the error it absorbs is no shift).
  std::map<std::string, double> shift;
  /// The names whose |shift| exceeds threshold x its predicted noise std, in the estimates' order.
  std::vector<std::string> matters;
};

struct ImuSensitivityResult {
  std::vector<std::string> names;            ///< every channel's coefficients, then the estimated errors
  std::map<std::string, std::string> units;  ///< name -> unit
  std::map<std::string, double> noise_std;   ///< name -> predicted std (the plan's, predict_imu_calibration)
  /// Channel coefficients the plan leaves unidentifiable ("gx.dIS"): no shift is stated for them.
  std::vector<std::string> not_identifiable;
  std::vector<ImuSensitivityRow> rows;
  double threshold = 0.1;
};

/// The study of `scenario` (an IMU, is_imu()): the base case its configured truth on a machine without
/// errors; each row (sensitivity_terms of its configured errors: its values, else the typical magnitudes)
/// that one error alone on the true machine while the calibration's model has none (the error not told),
/// least squares with `options.calibration.estimate` estimated as the configuration asks; planned outputs
/// (planned_imu_reductions), identify_imu on both. Rows on options.threads workers; results do not depend
/// on their number. Throws Error for a lone sensor's scenario, and as identify_imu does.
ImuSensitivityResult imu_sensitivity_study(const Scenario& scenario, const SensitivityOptions& options);

}  // namespace gyrocal
