#include "gyrocal/identify/predict.hpp"

#include <cmath>

#include "gyrocal/plan/positions.hpp"
#include "gyrocal/plan/timeline.hpp"

namespace gyrocal {

Reduction planned_reduction(const Scenario& s) {
  const CentrifugeModel model = s.model();
  const Timeline timeline = make_timeline(s.test, model);
  const double fs = s.test.sample_rate_hz, dt = 1.0 / fs;
  Reduction out;
  for (const MeasurementInterval& m : timeline.measurements) {
    Dwell d;
    d.is_static = m.kind == SegmentKind::kHold;
    d.planned_rate_rad_s = m.rate_rad_s;
    d.beta_rad = d.measured_beta_rad = m.beta_rad;
    d.gammas_rad = d.is_static ? std::vector<double>{m.gamma_rad} : s.test.gamma_rad;
    // The samples t_k = k / fs inside [start, end).
    const double k0 = std::ceil(m.start_s * fs - 1e-9), k1 = std::ceil(m.end_s * fs - 1e-9);
    d.first_time_s = k0 * dt;
    d.samples = static_cast<std::size_t>(k1 - k0);
    d.sample_interval_s = dt;
    d.last_time_s = d.first_time_s + static_cast<double>(d.samples - 1) * dt;
    d.planned_duration_s = m.end_s - m.start_s;
    const JointState j = joint_state_at(timeline, d.first_time_s);
    d.main = {j.main_angle_rad, j.main_rate_rad_s, 0.0};
    d.counter = {j.counter_angle_rad, j.counter_rate_rad_s, 0.0};
    d.gyro.value.assign(d.gammas_rad.size(), 0.0);
    d.gyro.std_err.assign(d.gammas_rad.size(), 0.0);
    d.gyro.samples.assign(d.gammas_rad.size(), d.samples);
    out.dwells.push_back(d);
  }
  for (const Position& p : test_positions(s.test)) {
    for (std::size_t di = 0; di < out.dwells.size(); ++di) {
      const Dwell& d = out.dwells[di];
      if (d.planned_rate_rad_s != p.rate_rad_s || d.beta_rad != p.beta_rad) continue;
      if (d.is_static && d.gammas_rad[0] != p.gamma_rad) continue;
      out.positions.push_back(reduced_position(p, d, static_cast<int>(di)));
      break;
    }
  }
  return out;
}

double white_noise_sample_std_deg_h(const GyroNoise& noise, double sample_rate_hz) {
  return noise.angle_random_walk_deg_rt_h * 60.0 * std::sqrt(sample_rate_hz);
}

void set_noise_free_outputs(Reduction& r, const std::vector<PositionChannels>& channels,
                            const DriftCoefficients& truth) {
  for (std::size_t i = 0; i < r.positions.size(); ++i) {
    const PositionChannels& ch = channels[i];
    double w = ch.omega_exact_deg_h;
    for (std::size_t k = 0; k < kNumCoefficients; ++k) w += truth.values[k] * ch.regressors_exact[k];
    r.positions[i].mean_deg_h = w;
  }
}

Eigen::MatrixXd predicted_position_covariance(const Reduction& r, const ReduceOptions& options,
                                              double sample_std_deg_h) {
  const auto n = static_cast<Eigen::Index>(r.positions.size());
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(n, n);
  std::vector<Eigen::MatrixXd> per_dwell;
  for (const Dwell& d : r.dwells) {
    // Every sample of the dwell, as the gyro output is reduced.
    DwellAccumulator acc(options, d.gammas_rad, d.is_static, 1, d.planned_duration_s, false);
    const double zero = 0.0;
    for (std::size_t i = 0; i < d.samples; ++i) {
      const double t = d.time_of_sample(i);
      acc.add(t, -d.counter.at(t, d.first_time_s), &zero);
    }
    per_dwell.push_back(acc.white_noise_covariance() * (sample_std_deg_h * sample_std_deg_h));
  }
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      const ReducedPosition& a = r.positions[static_cast<std::size_t>(i)];
      const ReducedPosition& b = r.positions[static_cast<std::size_t>(j)];
      if (a.dwell == b.dwell)
        cov(i, j) = per_dwell[static_cast<std::size_t>(a.dwell)](a.gamma_slot, b.gamma_slot);
    }
  return cov;
}

void set_predicted_std_errors(Reduction& r, const GyroNoise& noise, double sample_rate_hz,
                              const ReduceOptions& options) {
  const Eigen::MatrixXd cov =
      predicted_position_covariance(r, options, white_noise_sample_std_deg_h(noise, sample_rate_hz));
  for (Dwell& d : r.dwells) {
    const auto ng = static_cast<Eigen::Index>(d.gammas_rad.size());
    d.gyro.covariance = Eigen::MatrixXd::Zero(ng, ng);
  }
  for (std::size_t i = 0; i < r.positions.size(); ++i) {
    ReducedPosition& a = r.positions[i];
    a.std_err_deg_h = std::sqrt(cov(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)));
    for (std::size_t j = 0; j < r.positions.size(); ++j) {
      const ReducedPosition& b = r.positions[j];
      if (a.dwell == b.dwell)
        r.dwells[static_cast<std::size_t>(a.dwell)].gyro.covariance(a.gamma_slot, b.gamma_slot) =
            cov(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
    }
  }
  for (Dwell& d : r.dwells)
    for (std::size_t k = 0; k < d.gammas_rad.size(); ++k)
      d.gyro.std_err[k] =
          std::sqrt(d.gyro.covariance(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(k)));
}

CalibrationResult predict_calibration(const Scenario& s, const CalibrationOptions& options) {
  Reduction r = planned_reduction(s);
  const CentrifugeModel model = s.model();
  const std::vector<PositionChannels> channels = reduce_model_channels(r, model, options.reduce);
  set_noise_free_outputs(r, channels, s.gyro);
  set_predicted_std_errors(r, s.noise, s.test.sample_rate_hz, options.reduce);
  CalibrationResult result = identify(r, channels, model, options);
  if (s.noise.bias_instability_deg_h > 0 || s.noise.rate_random_walk_deg_h_rt_h > 0)
    result.warnings.push_back(
        "the predicted uncertainties count the angle random walk only; bias instability "
        "and rate random walk add to them.");
  if (s.noise.angle_random_walk_deg_rt_h == 0)
    result.warnings.push_back(
        "the configured angle random walk is zero: the predicted uncertainties are zero.");
  return result;
}

}  // namespace gyrocal
