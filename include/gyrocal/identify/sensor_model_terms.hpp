#pragma once
// The model's side of each reduced position for a sensor other than the gyro (docs/accelerometer.md, "The
// pipeline"): the sensor's design row (sensor/sensor_model.hpp: the known part of its output and the
// regressors of its products) evaluated at the exact inputs on each dwell's samples and reduced by the very
// operator that reduced the sensor's output, so that reduce(E) = reduce(known) + sum_j u_j reduce(r_j) holds
// exactly whatever harmonics the machine's errors add. The gyro keeps identify/model_terms.hpp's 25 columns.
#include <cstddef>
#include <vector>

#include "gyrocal/identify/model_terms.hpp"
#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/plan/test_spec.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/sensor/channel.hpp"
#include "gyrocal/sensor/sensor.hpp"

namespace gyrocal {

/// The arm angles, rad, at which a spinning dwell is reduced so that its values carry the harmonic fit's
/// whole content up to `harmonic_order`: 2 * order + 1 evenly spaced angles from 0 (the values at them and
/// the fit's 2 * order + 1 harmonic numbers are one invertible linear map of each other, so the values'
/// covariance from the fit is of full rank). Order 3: seven angles, 360/7 deg apart.
std::vector<double> harmonic_content_gammas_rad(int harmonic_order);

/// The plan a sensor's record is reduced with: `plan` itself for the gyro; for an accelerometer, each
/// spinning dwell reduced to harmonic_content_gammas_rad (TestSpec::spinning_gamma_rad) whatever [test]
/// gamma_deg lists, since values at the seed's four gammas fold the third harmonic onto the first and lose
/// K3 and the radius (docs/accelerometer.md). Static holds keep gamma_deg.
/// A design row's output at products u (the sensor's design-row order and units): known + sum_j u_j r_j, in
/// the output's unit. u holds at least row.size products.
double design_output(const DesignRow& row, const Eigen::VectorXd& u);

/// The sensor whose reduction a record of `channels` takes (reduction_plan's `sensor`): a lone sensor's own;
/// an IMU's an accelerometer's (a spinning dwell to the harmonic content of a revolution: its K3 and the
/// radius need it) when any channel is one, a gyro's reduction serving at any gamma, else a gyro's.
SensorKind reduction_kind(const std::vector<SensorChannel>& channels);

TestSpec reduction_plan(const TestSpec& plan, SensorKind sensor, const ReduceOptions& options);

/// Model terms of every position of `reduction`, in its order, for `channel`'s sensor on its axes on
/// `model`'s mount (sensor/channel.hpp: the platform's motion at each instant, then the channel's inputs on
/// it): PositionModelTerms::sensor_exact holds the reduced design row (the gyro's fields zero). Every sample
/// of a dwell is reduced (its stretches as the output has them; a planned dwell's evenly spaced instants): by
/// default (route kExact) from the design row's Fourier series in the two joint angles in closed form where
/// its check holds (reduce_dwell_by_fourier, as the gyro's model terms), else by evaluating every sample
/// (kEverySample, or a dwell that follows its measured motion); or every k-th sample as ReduceOptions::
/// model_samples_per_revolution and `max_samples_per_dwell` ask (as reduce_model_terms). `routes`, when
/// given, receives what was done per dwell.
std::vector<PositionModelTerms> reduce_sensor_model_terms(
    const Reduction& reduction, const CentrifugeModel& model, const ReduceOptions& options,
    const SensorChannel& channel, std::size_t max_samples_per_dwell = 0,
    ModelTermsRoute route = ModelTermsRoute::kExact, std::vector<DwellModelTermsRoute>* routes = nullptr);

}  // namespace gyrocal
