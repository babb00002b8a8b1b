#pragma once
// What the analyses (the sensitivity study, the Monte Carlo budget) read of a calibration: its estimates as
// one flat list of named numbers, each with its unit, stated std and the true value it estimates, for any
// sensor. One function over the sensor's parameter table, so that every analysis serves the gyro and the
// accelerometer alike (docs/accelerometer.md, "Sensitivity, Monte Carlo and report"); and the planned test of
// a sensor other than the gyro, reduced as its record would be.
#include <string>
#include <vector>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/model_terms.hpp"
#include "gyrocal/model/gyro.hpp"

namespace gyrocal {

/// One estimate of a calibration.
struct FlatEstimate {
  std::string name;  ///< "dI", "dI_1g", "K2", "K2 - Kpp", "scale_factor_error"
  std::string unit;  ///< its unit ("deg/h", "ug/g^2", "ppm")
  double value = 0.0;
  double std = 0.0;    ///< the standard uncertainty the calibration states
  double truth = 0.0;  ///< the scenario's true value of what it estimates (a combination's, for its weights)
  bool combination = false;  ///< one of CalibrationResult::combinations
};

/// The estimates of `r`, in order: the sensor's identifiable coefficients in its table's order (the gyro's
/// ten, then with drift+rate its identifiable rate errors; an accelerometer's eleven), the closed forms'
/// alternatives (the 1 g forms, estimating the coefficient they are named after), then the combinations
/// (NamedEstimate::coefficients weights the table's coefficients). True values from `truth`: its gyro and
/// gyro_rate, or its accelerometer's coefficients.
std::vector<FlatEstimate> flatten_estimates(const CalibrationResult& r, const Scenario& truth);

/// The white and coloured noise of a sensor other than the gyro in its output units, as the parameters of
/// the gyro's noise model that the prediction functions of analysis/predict.hpp take (per sample, the
/// accelerometer's white noise is K1 N sqrt(fs) 1e-6 output units, which the angle random walk K1 N 1e-6 / 60
/// gives; its bias instability K1 B 1e-6, its quantization K1 q 1e-6). The gyro: its [gyro.noise].
GyroNoise output_noise(const Scenario& scenario);

/// The planned test of `scenario`'s sensor other than the gyro: the dwells its record would give, reduced as
/// a calibration reduces them (an accelerometer's spinning dwells to their whole harmonic content,
/// identify/sensor_model_terms.hpp's reduction_plan), each position's output the noise-free reduced output of
/// the sensor's configured truth on `scenario`'s machine, its std error what the white noise predicts; and
/// the model terms of `told` (the machine the calibration is told) on the same dwells.
struct PlannedSensorTest {
  Reduction reduction;
  std::vector<PositionModelTerms> model_terms;
};
PlannedSensorTest planned_sensor_test(const Scenario& scenario, const CentrifugeModel& told,
                                      const ReduceOptions& options);

}  // namespace gyrocal
