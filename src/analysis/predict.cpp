#include "gyrocal/analysis/predict.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <limits>

#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/sensor_channels.hpp"
#include "gyrocal/plan/positions.hpp"
#include "gyrocal/plan/timeline.hpp"
#include "gyrocal/reduce/feasibility.hpp"
#include "gyrocal/simulate/noise.hpp"

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
    d.planned_counter_rate_offset_rad_s = m.counter_rate_offset_rad_s;
    d.beta_rad = d.measured_beta_rad = m.beta_rad;
    d.gammas_rad = d.is_static ? std::vector<double>{m.gamma_rad} : spinning_gammas(s.test);
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
      if (d.planned_rate_rad_s != p.rate_rad_s || d.beta_rad != p.beta_rad ||
          d.planned_counter_rate_offset_rad_s != p.counter_rate_offset_rad_s)
        continue;
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
                            const DriftCoefficients& truth, const GyroRateErrors& rate_errors) {
  for (std::size_t i = 0; i < r.positions.size(); ++i) {
    const PositionChannels& ch = channels[i];
    double w = ch.omega_exact_deg_h;
    for (std::size_t k = 0; k < kNumCoefficients; ++k) w += truth.values[k] * ch.regressors_exact[k];
    if (!rate_errors.is_zero()) {
      const double e = rate_errors.scale_factor_error_ppm * 1e-6;
      w += e * ch.omega_exact_deg_h +
           (1.0 + e) * kArcsecToRad *
               (rate_errors.input_axis_misalignment_O_arcsec * ch.omega_O_exact_deg_h +
                rate_errors.input_axis_misalignment_S_arcsec * ch.omega_S_exact_deg_h);
    }
    r.positions[i].mean_deg_h = w;
  }
}

namespace {

/// sum_{i<n} e^{j theta i} and sum_{i<n} i e^{j theta i}, in closed form (theta not a multiple of 2 pi):
/// e^{j phi} A and e^{j phi} ((n-1)/2 A - j A') with phi = (n-1) theta / 2, A = sin(n theta/2) /
/// sin(theta/2).
std::pair<std::complex<double>, std::complex<double>> power_sums(double theta, double n) {
  const double s = std::sin(0.5 * theta), c = std::cos(0.5 * theta);
  const double sn = std::sin(0.5 * n * theta), cn = std::cos(0.5 * n * theta);
  const double a = sn / s;
  const double da = (0.5 * n * cn * s - 0.5 * sn * c) / (s * s);
  const std::complex<double> rotation = std::polar(1.0, 0.5 * (n - 1.0) * theta);
  return {rotation * a, rotation * std::complex<double>(0.5 * (n - 1.0) * a, -da)};
}

/// The white-noise covariance of a spinning dwell's harmonic fit (reduce/dwell_accumulator.hpp: the basis
/// 1, cos k gamma, sin k gamma (k <= order) [, t scaled to [-0.5, 0.5] over the planned duration], the values
/// at the plan's gammas and mid-time) for the plan's samples: evenly spaced in time and, on constant-rate
/// joints, in gamma. The normal matrix's entries are sums of e^{j m gamma_i} and i e^{j m gamma_i} over the
/// samples, which have closed forms: the cost does not depend on the dwell's length (issue 11, item 9).
Eigen::MatrixXd harmonic_fit_covariance(const Dwell& d, const ReduceOptions& options) {
  const int order = options.harmonic_order;
  const int harmonics = 2 * order + 1;
  const int size = harmonics + (options.linear_drift ? 1 : 0);
  const double n = static_cast<double>(d.samples);
  // gamma_i = g0 + i step (the reducer's gamma is minus the counter platform's angle); t_i scaled = alpha i -
  // 1/2.
  const double g0 = -d.counter.at_first_rad, step = -d.counter.rate_rad_s * d.sample_interval_s;
  const double alpha = d.sample_interval_s / d.planned_duration_s, beta0 = -0.5;
  // E0[m] = sum_i e^{j m gamma_i}, E1[m] = sum_i i e^{j m gamma_i}, m = 0 .. 2 order.
  std::vector<std::complex<double>> e0(static_cast<std::size_t>(2 * order + 1)), e1(e0.size());
  e0[0] = n;
  e1[0] = 0.5 * n * (n - 1.0);
  for (int m = 1; m <= 2 * order; ++m) {
    const auto [s0, s1] = power_sums(m * step, n);
    const std::complex<double> phase = std::polar(1.0, m * g0);
    e0[static_cast<std::size_t>(m)] = phase * s0;
    e1[static_cast<std::size_t>(m)] = phase * s1;
  }
  const auto sum = [&](const std::vector<std::complex<double>>& e, int m) {
    return m >= 0 ? e[static_cast<std::size_t>(m)] : std::conj(e[static_cast<std::size_t>(-m)]);
  };
  // Basis index -> (harmonic k, is sine).
  const auto harmonic = [](int j) { return (j + 1) / 2; };
  const auto is_sine = [](int j) { return j > 0 && j % 2 == 0; };
  Eigen::MatrixXd normal(size, size);
  for (int a = 0; a < harmonics; ++a)
    for (int b = 0; b < harmonics; ++b) {
      const int ka = harmonic(a), kb = harmonic(b);
      const std::complex<double> diff = sum(e0, ka - kb), plus = sum(e0, ka + kb);
      double v;
      if (!is_sine(a) && !is_sine(b))
        v = 0.5 * (diff + plus).real();
      else if (is_sine(a) && is_sine(b))
        v = 0.5 * (diff - plus).real();
      else if (is_sine(a))  // sin ka cos kb
        v = 0.5 * (plus + diff).imag();
      else  // cos ka sin kb = sin kb cos ka
        v = 0.5 * (plus - diff).imag();
      normal(a, b) = v;
    }
  if (options.linear_drift) {
    const int t = harmonics;
    for (int a = 0; a < harmonics; ++a) {
      const std::complex<double> w = alpha * sum(e1, harmonic(a)) + beta0 * sum(e0, harmonic(a));
      normal(a, t) = normal(t, a) = is_sine(a) ? w.imag() : w.real();
    }
    const double si = 0.5 * n * (n - 1.0), sii = (n - 1.0) * n * (2.0 * n - 1.0) / 6.0;
    normal(t, t) = alpha * alpha * sii + 2.0 * alpha * beta0 * si + beta0 * beta0 * n;
  }
  const double t_mid = alpha * 0.5 * (n - 1.0) + beta0;
  const auto ng = static_cast<Eigen::Index>(d.gammas_rad.size());
  Eigen::MatrixXd basis(size, ng);
  for (Eigen::Index k = 0; k < ng; ++k) {
    const double g = d.gammas_rad[static_cast<std::size_t>(k)];
    basis(0, k) = 1.0;
    for (int h = 1; h <= order; ++h) {
      basis(2 * h - 1, k) = std::cos(h * g);
      basis(2 * h, k) = std::sin(h * g);
    }
    if (options.linear_drift) basis(harmonics, k) = t_mid;
  }
  return basis.transpose() * normal.ldlt().solve(basis);
}

}  // namespace

Eigen::MatrixXd dwell_white_noise_covariance(const Dwell& d, const ReduceOptions& options) {
  const auto ng = static_cast<Eigen::Index>(d.gammas_rad.size());
  if (d.samples == 0) return Eigen::MatrixXd::Constant(ng, ng, std::numeric_limits<double>::quiet_NaN());
  // A static hold's mean: 1/N.
  if (d.is_static) return Eigen::MatrixXd::Constant(ng, ng, 1.0 / static_cast<double>(d.samples));
  if (options.method == ReduceOptions::Method::kHarmonicFit && d.counter.rate_rad_s != 0.0)
    return harmonic_fit_covariance(d, options);
  // The window mean: every sample of the dwell, as the gyro output is reduced.
  DwellAccumulator acc(options, d.gammas_rad, d.is_static, 1, d.planned_duration_s, false);
  const double zero = 0.0;
  for (std::size_t i = 0; i < d.samples; ++i) {
    const double t = d.time_of_sample(i);
    acc.add(t, -d.counter.at(t, d.first_time_s), &zero);
  }
  return acc.white_noise_covariance();
}

Eigen::MatrixXd predicted_position_covariance(const Reduction& r, const ReduceOptions& options,
                                              double sample_std_deg_h) {
  const auto n = static_cast<Eigen::Index>(r.positions.size());
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(n, n);
  std::vector<Eigen::MatrixXd> per_dwell;
  for (const Dwell& d : r.dwells)
    per_dwell.push_back(dwell_white_noise_covariance(d, options) * (sample_std_deg_h * sample_std_deg_h));
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      const ReducedPosition& a = r.positions[static_cast<std::size_t>(i)];
      const ReducedPosition& b = r.positions[static_cast<std::size_t>(j)];
      if (a.dwell == b.dwell)
        cov(i, j) = per_dwell[static_cast<std::size_t>(a.dwell)](a.gamma_slot, b.gamma_slot);
    }
  return cov;
}

namespace {

/// The reduction operator of a dwell as rows over its samples: value of gamma slot g = sum_i a(g, i) y_i.
/// A static hold: the mean; a spinning dwell reduced by the harmonic fit: a_g = X M^-1 b_g with X the fit's
/// basis at the samples (as harmonic_fit_covariance), M = X'X and b_g the basis at gamma_g and mid-time.
/// Nothing for the window mean (its operator is not formed here).
std::optional<Eigen::MatrixXd> dwell_operator(const Dwell& d, const ReduceOptions& options) {
  const auto ng = static_cast<Eigen::Index>(d.gammas_rad.size());
  const auto n = static_cast<Eigen::Index>(d.samples);
  if (n == 0) return std::nullopt;
  if (d.is_static) return Eigen::MatrixXd::Constant(ng, n, 1.0 / static_cast<double>(n));
  if (options.method != ReduceOptions::Method::kHarmonicFit || d.counter.rate_rad_s == 0.0)
    return std::nullopt;
  const int order = options.harmonic_order;
  const int harmonics = 2 * order + 1;
  const int size = harmonics + (options.linear_drift ? 1 : 0);
  const double g0 = -d.counter.at_first_rad, step = -d.counter.rate_rad_s * d.sample_interval_s;
  const double alpha = d.sample_interval_s / d.planned_duration_s;
  const auto basis_at = [&](double gamma, double t_scaled, double* out) {
    out[0] = 1.0;
    for (int h = 1; h <= order; ++h) {
      out[2 * h - 1] = std::cos(h * gamma);
      out[2 * h] = std::sin(h * gamma);
    }
    if (options.linear_drift) out[harmonics] = t_scaled;
  };
  Eigen::MatrixXd x(size, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double fi = static_cast<double>(i);
    basis_at(g0 + fi * step, alpha * fi - 0.5, x.col(i).data());
  }
  const double t_mid = alpha * 0.5 * static_cast<double>(n - 1) - 0.5;
  Eigen::MatrixXd b(size, ng);
  for (Eigen::Index k = 0; k < ng; ++k)
    basis_at(d.gammas_rad[static_cast<std::size_t>(k)], t_mid, b.col(k).data());
  const Eigen::MatrixXd c = (x * x.transpose()).ldlt().solve(b);  // size x ng
  return c.transpose() * x;                                       // ng x n
}

}  // namespace

Eigen::MatrixXd coloured_noise_position_covariance(const Reduction& r, const ReduceOptions& options,
                                                   const GyroNoise& noise, double sample_rate_hz,
                                                   bool* complete) {
  const auto np = static_cast<Eigen::Index>(r.positions.size());
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(np, np);
  if (complete) *complete = true;
  const double b2 = noise.bias_instability_deg_h * noise.bias_instability_deg_h;
  const double walk_step = rate_random_walk_step_std_deg_h(noise.rate_random_walk_deg_h_rt_h, sample_rate_hz);
  const double s2 = walk_step * walk_step;
  if (b2 == 0.0 && s2 == 0.0) return cov;
  // The coloured noise's covariance is not in closed form: it walks the samples and holds each dwell's
  // operator (gammas x samples). Beyond kMaxColouredNoiseSamples it would take minutes and gigabytes, so it
  // is refused, never left out in silence (docs/performance.md, "plan in closed form").
  double total = 0.0;
  for (const Dwell& d : r.dwells) total += static_cast<double>(d.samples);
  if (total > kMaxColouredNoiseSamples)
    throw Error(fmt::format(
        "the bias instability and rate random walk are predicted by walking every sample of the dwells, and "
        "this test has {:.3g} of them, more than the {:.3g} that fit in memory: lower [test] revolutions (or "
        "sample_rate_hz), or set [gyro.noise] bias_instability_deg_h and rate_random_walk_deg_h_rt_h to 0 "
        "for the white noise's prediction alone.",
        total, kMaxColouredNoiseSamples));
  const std::size_t nd = r.dwells.size();
  std::vector<std::optional<Eigen::MatrixXd>> ops(nd);
  for (std::size_t d = 0; d < nd; ++d) {
    ops[d] = dwell_operator(r.dwells[d], options);
    if (!ops[d] && complete) *complete = false;
  }
  // Dwell-level covariance blocks (ng_d x ng_e), then scattered to the positions.
  std::vector<std::vector<Eigen::MatrixXd>> block(nd, std::vector<Eigen::MatrixXd>(nd));
  for (std::size_t d = 0; d < nd; ++d)
    for (std::size_t e = 0; e < nd; ++e)
      if (ops[d] && ops[e]) block[d][e] = Eigen::MatrixXd::Zero(ops[d]->rows(), ops[e]->rows());
  // Global sample index of a dwell's first sample (the record's sample k is at t = k / fs).
  const auto first_index = [&](const Dwell& d) { return std::round(d.first_time_s * sample_rate_hz); };

  // Bias instability: the simulator's sum of stationary Gauss-Markov processes, covariance
  // B^2 w_p e^{-|t - t'|/T_p} between samples (docs/noise.md). Within a dwell, K a_h by a forward and a
  // backward first-order recursion; across dwells the kernel factorises at the gap between them.
  if (b2 > 0.0) {
    for (std::size_t p = 0; p < kBiasInstabilityProcesses; ++p) {
      const double tp = kBiasInstabilityCorrelationTimesS[p], var = b2 * kBiasInstabilityVarianceWeights[p];
      std::vector<Eigen::VectorXd> left(nd), right(nd);  // sum_i a_gi rho^(N-1-i), sum_i a_gi rho^i
      for (std::size_t d = 0; d < nd; ++d) {
        if (!ops[d]) continue;
        const Eigen::MatrixXd& a = *ops[d];
        const Eigen::Index ng = a.rows(), n = a.cols();
        const double rho = std::exp(-r.dwells[d].sample_interval_s / tp);
        Eigen::MatrixXd ka(ng, n);
        left[d].resize(ng);
        right[d].resize(ng);
        for (Eigen::Index h = 0; h < ng; ++h) {
          Eigen::VectorXd forward(n), backward(n);
          double u = 0.0;
          for (Eigen::Index i = 0; i < n; ++i) forward[i] = u = rho * u + a(h, i);
          u = 0.0;
          for (Eigen::Index i = n - 1; i >= 0; --i) backward[i] = u = rho * u + a(h, i);
          ka.row(h) = (forward + backward - a.row(h).transpose()).transpose();
          left[d][h] = forward[n - 1];
          right[d][h] = backward[0];
        }
        block[d][d] += var * a * ka.transpose();
      }
      for (std::size_t d = 0; d < nd; ++d)
        for (std::size_t e = 0; e < nd; ++e) {
          if (d == e || !ops[d] || !ops[e]) continue;
          const Dwell &early = r.dwells[d], &late = r.dwells[e];
          if (!(early.last_time_s < late.first_time_s)) continue;  // each pair once, earlier dwell first
          const double gap = std::exp(-(late.first_time_s - early.last_time_s) / tp);
          const Eigen::MatrixXd c = var * gap * left[d] * right[e].transpose();
          block[d][e] += c;
          block[e][d] += c.transpose();
        }
    }
  }

  // Rate random walk: r_k = s sum_{m<k} n_m from the record's start, so cov(r_k, r_l) = s^2 min(k, l). Within
  // a dwell starting at sample k0: k0 (sum a_g)(sum a_h) + sum_{m>=1} S_g(m) S_h(m), S(m) = sum_{i>=m} a_i
  // (min(i, j) counts the m in 1..min(i, j)); across dwells (d before e): s^2 (sum_i a_gi k_i)(sum_j a_hj).
  if (s2 > 0.0) {
    std::vector<Eigen::VectorXd> sums(nd), index_moments(nd);
    for (std::size_t d = 0; d < nd; ++d) {
      if (!ops[d]) continue;
      const Eigen::MatrixXd& a = *ops[d];
      const Eigen::Index ng = a.rows(), n = a.cols();
      const double k0 = first_index(r.dwells[d]);
      sums[d] = a.rowwise().sum();
      index_moments[d].resize(ng);
      Eigen::MatrixXd tails(ng, n);  // tails(g, m) = S_g(m)
      for (Eigen::Index g = 0; g < ng; ++g) {
        double tail = 0.0, moment = 0.0;
        for (Eigen::Index i = n - 1; i >= 0; --i) {
          tail += a(g, i);
          tails(g, i) = tail;
          moment += a(g, i) * (k0 + static_cast<double>(i));
        }
        index_moments[d][g] = moment;
      }
      const Eigen::MatrixXd inner = tails.rightCols(n - 1) * tails.rightCols(n - 1).transpose();
      block[d][d] += s2 * (k0 * sums[d] * sums[d].transpose() + inner);
    }
    for (std::size_t d = 0; d < nd; ++d)
      for (std::size_t e = 0; e < nd; ++e) {
        if (d == e || !ops[d] || !ops[e]) continue;
        if (!(r.dwells[d].last_time_s < r.dwells[e].first_time_s)) continue;
        const Eigen::MatrixXd c = s2 * index_moments[d] * sums[e].transpose();
        block[d][e] += c;
        block[e][d] += c.transpose();
      }
  }

  for (Eigen::Index i = 0; i < np; ++i)
    for (Eigen::Index j = 0; j < np; ++j) {
      const ReducedPosition& a = r.positions[static_cast<std::size_t>(i)];
      const ReducedPosition& b = r.positions[static_cast<std::size_t>(j)];
      const Eigen::MatrixXd& c = block[static_cast<std::size_t>(a.dwell)][static_cast<std::size_t>(b.dwell)];
      if (c.size()) cov(i, j) = c(a.gamma_slot, b.gamma_slot);
    }
  return cov;
}

Eigen::MatrixXd predicted_noise_position_covariance(const Reduction& r, const ReduceOptions& options,
                                                    const GyroNoise& noise, double sample_rate_hz,
                                                    bool* complete) {
  return predicted_position_covariance(r, options, white_noise_sample_std_deg_h(noise, sample_rate_hz)) +
         coloured_noise_position_covariance(r, options, noise, sample_rate_hz, complete);
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

NoiseAllanVariances noise_allan_variances(const GyroNoise& noise, double tau_s) {
  const double white = 60.0 * noise.angle_random_walk_deg_rt_h / std::sqrt(tau_s);
  const double flicker = bias_instability_allan_deviation_deg_h(noise.bias_instability_deg_h, tau_s);
  const double walk = noise.rate_random_walk_deg_h_rt_h / 60.0 * std::sqrt(tau_s / 3.0);
  return {white * white, flicker * flicker, walk * walk};
}

std::string dominant_noise_warning(const GyroNoise& noise, double dwell_s) {
  if (!(dwell_s > 0.0)) return "";
  const NoiseAllanVariances v = noise_allan_variances(noise, dwell_s);
  const bool flicker = v.bias_instability > v.angle_random_walk;
  const bool walk = v.rate_random_walk > v.angle_random_walk;
  if (!flicker && !walk) return "";
  const char* which = flicker && walk ? "bias instability and rate random walk"
                      : flicker       ? "bias instability"
                                      : "rate random walk";
  return fmt::format(
      "at the dwell's duration of {:.3g} s, {} dominate{} the white noise: the Allan deviations there are "
      "{:.3g} deg/h (bias instability), {:.3g} deg/h (rate random walk) and {:.3g} deg/h (angle random "
      "walk), "
      "docs/physics.md section 13. More revolutions per position will not reduce the uncertainty; more "
      "positions or repeated sets will.",
      dwell_s, which, flicker && walk ? "" : "s", std::sqrt(v.bias_instability),
      std::sqrt(v.rate_random_walk), std::sqrt(v.angle_random_walk));
}

namespace {

/// Sets the standard uncertainty of every identifiable coefficient and combination of `result` to what the
/// positions' covariance `covariance` (white and coloured noise, across dwells) gives through the estimator:
/// the estimate is linear in the positions' outputs W, so its gain is found column by column by identifying
/// W0 + e_k (the same weights as `result`'s, which the white noise sets: a calibration of a record weights
/// its dwells the same way), and the variance of an estimate with gain g is g' C g.
void count_whole_noise(CalibrationResult& result, const Reduction& r,
                       const std::vector<PositionChannels>& channels, const CentrifugeModel& model,
                       const CalibrationOptions& options, const Eigen::MatrixXd& covariance) {
  const auto np = static_cast<Eigen::Index>(r.positions.size());
  // The estimates: the coefficients, then the combinations, then the closed form's alternatives.
  std::vector<double*> stds;
  std::vector<double> base;
  std::vector<std::function<double(const CalibrationResult&)>> value_of;
  for (std::size_t c = 0; c < kNumCoefficients; ++c)
    if (result.coefficients[c].identifiable) {
      stds.push_back(&result.coefficients[c].std);
      value_of.push_back([c](const CalibrationResult& e) { return e.coefficients[c].value; });
    }
  for (auto* list : {&result.combinations, &result.alternatives})
    for (NamedEstimate& est : *list) {
      stds.push_back(&est.std);
      const bool combination = list == &result.combinations;
      value_of.push_back([name = est.name, combination](const CalibrationResult& e) {
        for (const NamedEstimate& x : combination ? e.combinations : e.alternatives)
          if (x.name == name) return x.value;
        return std::numeric_limits<double>::quiet_NaN();
      });
    }
  for (const auto& f : value_of) base.push_back(f(result));
  Eigen::MatrixXd gain(static_cast<Eigen::Index>(stds.size()), np);
  for (Eigen::Index k = 0; k < np; ++k) {
    Reduction shifted = r;
    shifted.positions[static_cast<std::size_t>(k)].mean_deg_h += 1.0;
    const CalibrationResult e = identify(shifted, channels, model, options);
    for (std::size_t i = 0; i < stds.size(); ++i)
      gain(static_cast<Eigen::Index>(i), k) = value_of[i](e) - base[i];
  }
  for (std::size_t i = 0; i < stds.size(); ++i) {
    const Eigen::VectorXd g = gain.row(static_cast<Eigen::Index>(i)).transpose();
    *stds[i] = std::sqrt(g.dot(covariance * g));
  }
}

}  // namespace

namespace {

/// predict_calibration for a sensor other than the gyro (docs/accelerometer.md, "Planning"): the planned
/// dwells reduced as its record would be (an accelerometer's spinning dwells to their whole harmonic
/// content), its design rows on every planned sample, noise-free outputs from its configured truth, the
/// reduced values' covariance from its white noise, then the calibration's own identification.
CalibrationResult predict_sensor_calibration(const Scenario& s, const CalibrationOptions& options) {
  Scenario planned = s;
  planned.test = reduction_plan(s.test, s.sensor_kind, options.reduce);
  Reduction r = planned_reduction(planned);
  const CentrifugeModel model = s.model();
  const Sensor sensor = s.sensor();
  const std::vector<PositionChannels> channels = reduce_sensor_channels(r, model, options.reduce, sensor);
  const Accelerometer& a = std::get<Accelerometer>(sensor);
  const Eigen::VectorXd u = a.products();
  for (std::size_t i = 0; i < r.positions.size(); ++i) {
    const DesignRow& row = channels[i].sensor_exact;
    double e = row.known;
    for (std::size_t k = 0; k < row.size; ++k) e += row.regressors[k] * u[static_cast<Eigen::Index>(k)];
    r.positions[i].mean_deg_h = e;
  }
  // The white noise as the simulator draws it (simulate/accelerometer_noise.hpp): per sample N sqrt(fs) ug
  // referred to the input, K1 times that in output units; the gyro's white term with that sample std.
  GyroNoise white;
  white.angle_random_walk_deg_rt_h =
      a.noise.velocity_random_walk_ug_rt_hz * 1e-6 * std::abs(a.coefficients[AccelCoefficient::K1]) / 60.0;
  set_predicted_std_errors(r, white, s.test.sample_rate_hz, options.reduce);
  CalibrationOptions identify_options = options;
  identify_options.least_squares.chi2_warning_sigma = std::numeric_limits<double>::infinity();
  CalibrationResult result = identify(r, channels, model, identify_options);
  if (a.noise.bias_instability_ug > 0.0)
    result.warnings.push_back(
        "the predicted uncertainties count the accelerometer's white noise only: its bias instability adds "
        "to "
        "them.");
  if (a.noise.velocity_random_walk_ug_rt_hz == 0.0)
    result.warnings.push_back(
        "the configured accelerometer noise is zero: the predicted uncertainties are zero.");
  return result;
}

}  // namespace

CalibrationResult predict_calibration(const Scenario& s, const CalibrationOptions& options) {
  // What calibrate would refuse, plan refuses too, by the same check (issue 11, item 6).
  check_test_feasible(s.test, options.reduce, s.centrifuge.rate_rad_s);
  if (s.sensor_kind != SensorKind::kGyro) return predict_sensor_calibration(s, options);
  Reduction r = planned_reduction(s);
  const CentrifugeModel model = s.model();
  // A bounded number of model evaluations per dwell: the prediction's cost does not grow with the test.
  const std::vector<PositionChannels> channels =
      reduce_model_channels(r, model, options.reduce, kMaxModelSamplesPerDwell);
  set_noise_free_outputs(r, channels, s.gyro, s.gyro_rate);
  set_predicted_std_errors(r, s.noise, s.test.sample_rate_hz, options.reduce);
  // The predicted outputs are noise-free, so chi2 is ~0 by construction: its test against the degrees of
  // freedom says nothing about a plan and must not warn.
  CalibrationOptions identify_options = options;
  identify_options.least_squares.chi2_warning_sigma = std::numeric_limits<double>::infinity();
  // A self-calibration's Jacobian evaluated on the same bounded samples as the channels.
  identify_options.max_model_samples_per_dwell = kMaxModelSamplesPerDwell;
  CalibrationResult result = identify(r, channels, model, identify_options);
  // The Allan variances compared at the longest dwell's duration: where the colored noise dominates,
  // averaging longer stops paying (issue 10, item 2).
  double longest_dwell_s = 0.0;
  for (const Dwell& d : r.dwells) longest_dwell_s = std::max(longest_dwell_s, d.planned_duration_s);
  if (std::string w = dominant_noise_warning(s.noise, longest_dwell_s); !w.empty())
    result.warnings.push_back(std::move(w));
  if (s.noise.bias_instability_deg_h > 0 || s.noise.rate_random_walk_deg_h_rt_h > 0) {
    bool complete = true;
    const Eigen::MatrixXd covariance =
        predicted_noise_position_covariance(r, options.reduce, s.noise, s.test.sample_rate_hz, &complete);
    count_whole_noise(result, r, channels, model, identify_options, covariance);
    if (!complete)
      result.warnings.push_back(
          "the predicted uncertainties leave out the bias instability and rate random walk of the dwells "
          "reduced by the window mean; they add to them.");
  } else if (s.noise.angle_random_walk_deg_rt_h == 0) {
    result.warnings.push_back("the configured gyro noise is zero: the predicted uncertainties are zero.");
  }
  return result;
}

}  // namespace gyrocal
