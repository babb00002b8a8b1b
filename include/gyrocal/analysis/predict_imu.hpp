#pragma once
// Before an IMU's test is run (docs/imu.md, "Planning an IMU"): what its calibration will give, per channel,
// from the plan and each channel's configured noise, through the same joint solve a record gets.
#include <vector>

#include <Eigen/Core>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/imu_calibration.hpp"
#include "gyrocal/simulate/noise.hpp"

namespace gyrocal {

/// The true products of a channel's sensor, in its design row's order and units (identify/sensor_model_terms
/// .hpp): a gyro's ten drift coefficients (deg/h, deg/h/g, deg/h/g^2) and with drift+rate its e (ppm),
/// (1 + e) dO and (1 + e) dS (arcsec); an accelerometer's products (Accelerometer::products, its K1 the
/// channel's ratio to its output_scale).
Eigen::VectorXd true_products(const Sensor& sensor);

/// A channel's configured noise as the noise generators' parameters in the unit its positions are reduced
/// in (the sensor's: deg/h for a gyro; an accelerometer's output per g times g, K1 x 1e-6 per ug): what
/// set_predicted_std_errors takes.
GyroNoise channel_output_noise(const Sensor& sensor);

/// The plan's dwells as calibrate_imu_record reduces a record of them (reduction_plan of reduction_kind), one
/// reduction per channel (its positions numbered with the channel), each position's mean the channel's
/// noise-free reduced output at its configured truth on the machine `truth`, its standard errors from its
/// configured white noise (set_predicted_std_errors with channel_output_noise).
std::vector<Reduction> planned_imu_reductions(const Scenario& scenario, const CentrifugeModel& truth,
                                              const ReduceOptions& reduce);

/// `options` for identify_imu on noise-free planned reductions: no misfit, flat top or sign tested (chi2 is
/// zero by construction), the model terms on the bounded samples a prediction takes.
CalibrationOptions planned_identify_options(const CalibrationOptions& options);

/// `gyrocal plan` of an IMU: the plan's dwells reduced as calibrate_imu_record reduces a record of it (to the
/// harmonic content of a revolution when any channel is an accelerometer), every channel's noise-free outputs
/// from its configured truth on the configured machine, its positions' standard errors from its configured
/// noise (white and coloured, as the lone sensor's plan), then identify_imu: per channel its predicted
/// standard uncertainties and identifiability, the shared errors' (options.estimate), the triad's geometry.
/// The estimates are the configured truth; chi2 is zero by construction and not tested.
ImuCalibrationResult predict_imu_calibration(const Scenario& scenario, const CalibrationOptions& options);

}  // namespace gyrocal
