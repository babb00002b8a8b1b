#include "gyrocal/analysis/estimates.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/analysis/predict_imu.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/identify/unknowns.hpp"
#include "gyrocal/plan/positions.hpp"

namespace gyrocal {

std::vector<FlatEstimate> flatten_estimates(const CalibrationResult& r, const Scenario& truth) {
  std::vector<FlatEstimate> out;
  // The true values of the sensor's table, in its order: what a combination's weights apply to.
  std::vector<double> table_truth;
  if (r.sensor == SensorKind::kGyro) {
    table_truth.assign(truth.gyro.values.begin(), truth.gyro.values.end());
    // docs/physics.md section 15: the rate errors, in ppm and arcsec, where the gyro model identifies them.
    for (double v : {truth.gyro_rate.scale_factor_error_ppm, truth.gyro_rate.input_axis_misalignment_O_arcsec,
                     truth.gyro_rate.input_axis_misalignment_S_arcsec})
      table_truth.push_back(v);
  } else {
    const Sensor sensor = truth.sensor();
    if (const auto* a = std::get_if<Accelerometer>(&sensor))
      table_truth.assign(a->coefficients.values.begin(), a->coefficients.values.end());
  }
  // The sensor's identifiable coefficients, by its table (CalibrationResult::coefficients), with their truth.
  table_truth.resize(std::max(table_truth.size(), r.coefficients.size()), 0.0);
  for (std::size_t k = 0; k < r.coefficients.size(); ++k) {
    const CoefficientEstimate& c = r.coefficients[k];
    if (c.identifiable) out.push_back({c.name, c.unit, c.value, c.std, table_truth[k]});
  }
  if (r.sensor == SensorKind::kGyro && r.method == Method::kClosedForm) {
    // The 1 g forms estimate the same coefficients as the primary ones (docs/physics.md section 8).
    const std::pair<const char*, Coefficient> of[] = {{"dI_1g", Coefficient::dI},
                                                      {"dO_1g", Coefficient::dO},
                                                      {"dS_1g", Coefficient::dS},
                                                      {"dIS_b", Coefficient::dIS}};
    for (const NamedEstimate& e : r.alternatives)
      for (const auto& [n, c] : of)
        if (e.name == n) out.push_back({e.name, e.unit, e.value, e.std, truth.gyro[c]});
  }
  for (const NamedEstimate& e : r.combinations) {
    double t = 0.0;
    for (std::size_t k = 0; k < e.coefficients.size() && k < table_truth.size(); ++k)
      t += e.coefficients[k] * table_truth[k];
    out.push_back({e.name, e.unit, e.value, e.std, t, true});
  }
  return out;
}

GyroNoise output_noise(const Scenario& s) {
  // A lone gyro's [gyro.noise]; a lone accelerometer's as an IMU channel's (analysis/predict_imu.hpp).
  if (s.sensor_kind == SensorKind::kGyro) return s.noise;
  return channel_output_noise(Sensor{s.accelerometer});
}

PlannedSensorTest planned_sensor_test(const Scenario& s, const CentrifugeModel& told,
                                      const ReduceOptions& options) {
  Scenario planned = s;
  planned.test = reduction_plan(s.test, s.sensor_kind, options);
  PlannedSensorTest p;
  p.reduction = planned_reduction(planned);
  const SensorChannel channel = s.channels().front();
  const Sensor& sensor = channel.sensor;
  // The sensor's truth on the true machine: known + sum_j u_j r_j, u its products.
  const std::vector<PositionModelTerms> truth =
      reduce_sensor_model_terms(p.reduction, s.model(), options, channel, kMaxModelSamplesPerDwell);
  Eigen::VectorXd u;
  if (const auto* a = std::get_if<Accelerometer>(&sensor)) u = a->products();
  for (std::size_t i = 0; i < p.reduction.positions.size(); ++i) {
    const DesignRow& row = truth[i].sensor_exact;
    double e = row.known;
    for (std::size_t k = 0; k < row.size && static_cast<Eigen::Index>(k) < u.size(); ++k)
      e += row.regressors[k] * u[static_cast<Eigen::Index>(k)];
    p.reduction.positions[i].mean = e;
  }
  set_predicted_std_errors(p.reduction, output_noise(s), s.test.sample_rate_hz, options);
  p.model_terms = reduce_sensor_model_terms(p.reduction, told, options, channel, kMaxModelSamplesPerDwell);
  return p;
}

}  // namespace gyrocal
