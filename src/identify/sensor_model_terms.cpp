// A sensor's model columns (its design row) and how a reduced position's columns become its
// PositionModelTerms; the reduction itself is the one per-dwell model route's
// (identify/dwell_model_route.hpp).
#include "gyrocal/identify/sensor_model_terms.hpp"

#include <algorithm>

#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/dwell_model_route.hpp"

namespace gyrocal {
namespace {

/// The channel's design row at the joints (the encoders at the output's stamp) as the reduction's columns:
/// the known part, then the regressors; at the inputs the output holds (the platform's motion the
/// acquisition's delay earlier, sensed_platform_motion, evaluated at the channel).
void design_columns(const SensorChannel& channel, const CentrifugeModel& model, const JointState& j,
                    double* out) {
  const DesignRow row =
      sensor_design_row(channel.sensor, channel_inputs(model, sensed_platform_motion(model, j), channel));
  out[0] = row.known;
  for (std::size_t k = 0; k < row.size; ++k) out[k + 1] = row.regressors[k];
}

}  // namespace

std::vector<double> harmonic_content_gammas_rad(int harmonic_order) {
  const int n = 2 * std::max(harmonic_order, 0) + 1;
  std::vector<double> out;
  for (int k = 0; k < n; ++k) out.push_back(2.0 * kPi * k / n);
  return out;
}

double design_output(const DesignRow& row, const Eigen::VectorXd& u) {
  double v = row.known;
  for (std::size_t k = 0; k < row.size; ++k) v += row.regressors[k] * u[static_cast<Eigen::Index>(k)];
  return v;
}

SensorKind reduction_kind(const std::vector<SensorChannel>& channels) {
  const bool any_accelerometer = std::any_of(channels.begin(), channels.end(), [](const SensorChannel& c) {
    return kind_of(c.sensor) == SensorKind::kAccelerometer;
  });
  return any_accelerometer ? SensorKind::kAccelerometer : SensorKind::kGyro;
}

TestSpec reduction_plan(const TestSpec& plan, SensorKind sensor, const ReduceOptions& options) {
  TestSpec out = plan;
  if (sensor == SensorKind::kAccelerometer && options.method == ReduceOptions::Method::kHarmonicFit)
    out.spinning_gamma_rad = harmonic_content_gammas_rad(options.harmonic_order);
  return out;
}

std::vector<PositionModelTerms> reduce_sensor_model_terms(
    const Reduction& reduction, const CentrifugeModel& model, const ReduceOptions& options,
    const SensorChannel& channel, std::size_t max_samples_per_dwell, ModelTermsRoute route,
    std::vector<DwellModelTermsRoute>* routes) {
  const DesignRow probe = sensor_design_row(channel.sensor, exact_inputs(model, JointState{}));
  const int columns = 1 + static_cast<int>(probe.size);
  // An accelerometer's design row is in the output's unit and its powers (g, g^2, g^3): no column is a
  // difference of the joints' rates. A gyro's known part is its input rate omega_I in deg/h: a difference of
  // the arm's and the counter platform's rates (2.5e6 deg/h each at 12 rad/s), whose rounding the Fourier
  // route's check measures against the rates (kRateRounding), as the gyro's own columns are
  // (reduce_model_terms); measured against its own small size it failed the check at every spinning dwell
  // and took every sample. Its regressors (g and its products; a drift+rate gyro's rate terms scaled by 1e-6
  // and 1 arcsec) stay regressors.
  DwellModelRoute design;
  design.columns = columns;
  design.rate_columns.assign(static_cast<std::size_t>(columns), false);
  if (kind_of(channel.sensor) == SensorKind::kGyro) design.rate_columns[0] = true;
  // Where the route's choices differ by sensor, a sensor keeps those it had before the route was one: each
  // other choice moves an accelerometer's plans' or calibrations' numbers (the two closed forms agree to
  // ~1e-11, not bit for bit; the two strides take other samples). Planned dwells by the Fourier closed forms
  // (the planned closed form was written for the gyro's columns before a sensor's route existed, and was
  // never taken here); a prediction's bound spread evenly over the samples, static holds too; where a dwell
  // follows its measured motion, the per-revolution fits beside it: an accelerometer reads the centripetal
  // force, first order in the rate, so its model changes from one revolution to the next and identify takes
  // the scatter of the output minus the model between revolutions (PositionModelTerms::sensor_periods;
  // docs/accelerometer_internals.md).
  design.stride_bound = ModelStrideBound::kEvenSpread;
  design.per_revolution = true;
  // An output written as increments is the mean over each sample's interval: so is its model
  // (docs/records.md, "Increments"). A rate's stays the value at the stamp.
  design.interval_mean = channel.output.form == OutputForm::kIncrement;
  const std::vector<DwellModelValues> per_dwell = reduce_dwells_model(
      reduction, model, options, max_samples_per_dwell, route, design,
      [&](const Dwell&, const JointState& j, double* row) { design_columns(channel, model, j, row); });
  if (routes) *routes = dwell_routes(per_dwell);
  std::vector<PositionModelTerms> out;
  for (const ReducedPosition& p : reduction.positions) {
    const auto at = [&](int c) { return position_column(per_dwell, p, c); };
    PositionModelTerms ch;
    ch.sensor_exact.known = at(0);
    ch.sensor_exact.size = probe.size;
    for (std::size_t k = 0; k < probe.size; ++k) ch.sensor_exact.regressors[k] = at(static_cast<int>(k) + 1);
    for (const auto& [index, values] : per_dwell[static_cast<std::size_t>(p.dwell)].revolutions) {
      PositionModelTerms::PeriodRow pr;
      pr.index = index;
      const auto g = static_cast<Eigen::Index>(p.gamma_slot);
      pr.row.known = values(g, 0);
      pr.row.size = probe.size;
      for (std::size_t k = 0; k < probe.size; ++k)
        pr.row.regressors[k] = values(g, static_cast<Eigen::Index>(k) + 1);
      ch.sensor_periods.push_back(pr);
    }
    out.push_back(ch);
  }
  return out;
}

}  // namespace gyrocal
