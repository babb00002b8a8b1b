// An IMU's plan (analysis/predict_imu.hpp): the lone sensor's prediction (analysis/predict.hpp) per channel,
// then the joint solve of a record (identify/imu_calibration.hpp).
#include "gyrocal/analysis/predict_imu.hpp"

#include <cmath>
#include <limits>

#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/reduce/feasibility.hpp"
#include "gyrocal/simulate/accelerometer_noise.hpp"

namespace gyrocal {

Eigen::VectorXd true_products(const Sensor& sensor) {
  if (const auto* a = std::get_if<Accelerometer>(&sensor)) return a->products();
  const Gyro& g = std::get<Gyro>(sensor);
  Eigen::VectorXd u(static_cast<Eigen::Index>(g.num_unknowns()));
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) u[static_cast<Eigen::Index>(k)] = g.drift.values[k];
  if (g.model == GyroModel::kDriftRate) {
    const double e = g.rate.scale_factor_error_ppm;
    const auto at = static_cast<Eigen::Index>(kNumGyroCoefficients);
    u[at] = e;
    u[at + 1] = (1.0 + e * 1e-6) * g.rate.input_axis_misalignment_O_arcsec;
    u[at + 2] = (1.0 + e * 1e-6) * g.rate.input_axis_misalignment_S_arcsec;
  }
  return u;
}

GyroNoise channel_output_noise(const Sensor& sensor) {
  if (const auto* g = std::get_if<Gyro>(&sensor)) return g->noise;
  // As the simulator draws it (simulate/accelerometer_noise.hpp): the generators in ug referred to the input,
  // times K1 x 1e-6 in output units (a lone accelerometer's too: analysis/estimates.hpp output_noise).
  const Accelerometer& a = std::get<Accelerometer>(sensor);
  GyroNoise n = accelerometer_noise_as_generator_parameters(a.noise);
  const double scale = 1e-6 * std::abs(a.coefficients[AccelCoefficient::K1]);
  n.angle_random_walk_deg_rt_h *= scale;
  n.bias_instability_deg_h *= scale;
  n.quantization_deg_h *= scale;
  return n;
}

std::vector<Reduction> planned_imu_reductions(const Scenario& s, const CentrifugeModel& truth,
                                              const ReduceOptions& reduce) {
  const std::vector<SensorChannel>& channels = s.channels();
  Scenario planned = s;
  planned.test = reduction_plan(s.test, reduction_kind(channels), reduce);
  const Reduction plan = planned_reduction(planned);
  std::vector<Reduction> reductions;
  for (const SensorChannel& c : channels) {
    Reduction r = plan;
    for (ReducedPosition& p : r.positions) p.channel = static_cast<int>(reductions.size());
    const std::vector<PositionModelTerms> terms =
        reduce_sensor_model_terms(r, truth, reduce, c, kMaxModelSamplesPerDwell);
    const Eigen::VectorXd u = true_products(c.sensor);
    for (std::size_t i = 0; i < r.positions.size(); ++i)
      r.positions[i].mean = design_output(terms[i].sensor_exact, u);
    set_predicted_std_errors(r, channel_output_noise(c.sensor), s.test.sample_rate_hz, reduce);
    reductions.push_back(std::move(r));
  }
  return reductions;
}

CalibrationOptions planned_identify_options(const CalibrationOptions& options) {
  CalibrationOptions o = options;
  o.test_misfit = false;
  o.least_squares.chi2_warning_sigma = std::numeric_limits<double>::infinity();
  o.max_model_samples_per_dwell = kMaxModelSamplesPerDwell;
  return o;
}

ImuCalibrationResult predict_imu_calibration(const Scenario& s, const CalibrationOptions& options) {
  check_test_feasible(s.test, options.reduce, s.centrifuge.rate_rad_s);
  const std::vector<SensorChannel>& channels = s.channels();
  const CentrifugeModel model = s.model();
  ImuCalibrationResult result = identify_imu(planned_imu_reductions(s, model, options.reduce), channels,
                                             model, planned_identify_options(options), {});
  for (const SensorChannel& c : channels) {
    const GyroNoise n = channel_output_noise(c.sensor);
    const bool coloured =
        n.bias_instability_deg_h > 0.0 || n.rate_random_walk_deg_h_rt_h > 0.0 || n.quantization_deg_h > 0.0;
    if (n.angle_random_walk_deg_rt_h == 0.0 && !coloured)
      result.warnings.push_back("channel " + c.name +
                                ": its configured noise is zero: its predicted uncertainties are zero.");
    else if (coloured)
      // The lone sensor's plan counts the noise correlated across positions through each estimate's gains
      // (predict_calibration); the joint solve's plan does not yet.
      result.warnings.push_back(
          "channel " + c.name +
          ": the predicted uncertainties count its white noise only; its bias instability, rate random walk "
          "and quantization add to them (docs/imu.md, \"Planning an IMU\").");
  }
  return result;
}

}  // namespace gyrocal
