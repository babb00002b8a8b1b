#include "gyrocal/analysis/predict.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <functional>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <limits>

#include "gyrocal/analysis/estimates.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/plan/positions.hpp"
#include "gyrocal/plan/timeline.hpp"
#include "gyrocal/reduce/dwell_reduction.hpp"
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
    d.output.value.assign(d.gammas_rad.size(), 0.0);
    d.output.std_err.assign(d.gammas_rad.size(), 0.0);
    d.output.samples.assign(d.gammas_rad.size(), d.samples);
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

void set_noise_free_outputs(Reduction& r, const std::vector<PositionModelTerms>& model_terms,
                            const DriftCoefficients& truth, const GyroRateErrors& rate_errors) {
  for (std::size_t i = 0; i < r.positions.size(); ++i) {
    const PositionModelTerms& ch = model_terms[i];
    double w = ch.omega_exact_deg_h;
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) w += truth.values[k] * ch.regressors_exact[k];
    if (!rate_errors.is_zero()) {
      const double e = rate_errors.scale_factor_error_ppm * 1e-6;
      w += e * ch.omega_exact_deg_h +
           (1.0 + e) * kArcsecToRad *
               (rate_errors.input_axis_misalignment_O_arcsec * ch.omega_O_exact_deg_h +
                rate_errors.input_axis_misalignment_S_arcsec * ch.omega_S_exact_deg_h);
    }
    r.positions[i].mean = w;
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

/// The sums over i < count of the linear recurrence z_{i+1} = B z_i from z_0: sum_i z_i z_i' (gram), sum_i
/// z_i (sum) and z_{count-1} (last; zero when count is 0). By doubling: a block of 2^k steps is two blocks of
/// 2^(k-1), the second the first mapped by B^(2^(k-1)) (gram(m + l) = gram(m) + B^m gram(l) B^m'), so the
/// cost is O(log count) products of D x D matrices and the rounding grows as log count, but for the powers of
/// B themselves (a rotation's phase after count steps carries ~count eps, as does count * step in any route).
struct RecurrenceSums {
  Eigen::MatrixXd gram;
  Eigen::VectorXd sum;
  Eigen::VectorXd last;
};

RecurrenceSums recurrence_sums(const Eigen::MatrixXd& b, const Eigen::VectorXd& z0, std::uint64_t count) {
  const Eigen::Index dim = z0.size();
  RecurrenceSums out{Eigen::MatrixXd::Zero(dim, dim), Eigen::VectorXd::Zero(dim), Eigen::VectorXd::Zero(dim)};
  Eigen::MatrixXd power = b, gram = z0 * z0.transpose(), prefix = Eigen::MatrixXd::Identity(dim, dim);
  Eigen::VectorXd sum = z0, last = z0;  // the block of 2^k steps: B^(2^k), its gram, sum and last state
  while (count > 0) {
    if (count & 1u) {  // append the block after the `prefix` steps taken so far
      out.gram += prefix * gram * prefix.transpose();
      out.sum += prefix * sum;
      out.last = prefix * last;
      prefix = prefix * power;
    }
    count >>= 1;
    if (count == 0) break;
    gram += power * gram * power.transpose();
    sum += power * sum;
    last = power * last;
    power = power * power;
  }
  return out;
}

/// The Kronecker product a (x) b.
Eigen::MatrixXd kron(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  Eigen::MatrixXd out(a.rows() * b.rows(), a.cols() * b.cols());
  for (Eigen::Index i = 0; i < a.rows(); ++i)
    for (Eigen::Index j = 0; j < a.cols(); ++j)
      out.block(i * b.rows(), j * b.cols(), b.rows(), b.cols()) = a(i, j) * b;
  return out;
}

/// M^m for a small square matrix, by squaring.
Eigen::MatrixXd matrix_power(const Eigen::MatrixXd& m, std::uint64_t count) {
  Eigen::MatrixXd out = Eigen::MatrixXd::Identity(m.rows(), m.cols()), p = m;
  for (; count > 0; count >>= 1) {
    if (count & 1u) out = out * p;
    p = p * p;
  }
  return out;
}

/// A dwell's reduction as a linear map of its samples: the value of gamma slot g is sum_i (c_g' x_i) y_i, x_i
/// the basis at sample i. A static hold: x_i = 1, c = 1/N (the mean). A spinning dwell reduced by the
/// harmonic fit: x_i = (1, cos k gamma_i, sin k gamma_i (k <= order) [, t_i scaled to [-0.5, 0.5] over the
/// planned duration]), c_g = M^-1 b_g with M = sum_i x_i x_i' and b_g the basis at gamma_g and the mid-time.
/// On the plan's constant-rate joints x_{i+1} = A x_i: rotations by k (gamma step) and t's step alpha (times
/// the constant 1). None for the window mean (its operator is not formed here).
struct DwellBasis {
  Eigen::MatrixXd step;          ///< A: x_{i+1} = A x_i
  Eigen::MatrixXd back;          ///< A^-1: x_{i-1} = A^-1 x_i
  Eigen::VectorXd first, last;   ///< x_0, x_{N-1}
  Eigen::MatrixXd coefficients;  ///< c: basis size x gammas
  std::uint64_t samples = 0;     ///< N
  double first_index = 0.0;      ///< the record's index of sample 0 (t = k / fs)
};

std::optional<DwellBasis> dwell_basis(const Dwell& d, const ReduceOptions& options, double sample_rate_hz) {
  const auto ng = static_cast<Eigen::Index>(d.gammas_rad.size());
  if (d.samples == 0) return std::nullopt;
  DwellBasis out;
  out.samples = d.samples;
  out.first_index = std::round(d.first_time_s * sample_rate_hz);
  const double n = static_cast<double>(d.samples);
  if (d.is_static) {
    out.step = out.back = Eigen::MatrixXd::Identity(1, 1);
    out.first = out.last = Eigen::VectorXd::Ones(1);
    out.coefficients = Eigen::MatrixXd::Constant(1, ng, 1.0 / n);
    return out;
  }
  if (options.method != ReduceOptions::Method::kHarmonicFit || d.counter.rate_rad_s == 0.0)
    return std::nullopt;
  const int order = options.harmonic_order;
  const int harmonics = 2 * order + 1;
  const int size = harmonics + (options.linear_drift ? 1 : 0);
  const double g0 = -d.counter.at_first_rad, step = -d.counter.rate_rad_s * d.sample_interval_s;
  const double alpha = d.sample_interval_s / d.planned_duration_s;
  const auto basis_at = [&](double gamma, double t_scaled) {
    Eigen::VectorXd x(size);
    harmonic_basis(gamma, order, x.data());
    if (options.linear_drift) x[harmonics] = t_scaled;
    return x;
  };
  const auto step_matrix = [&](double sign) {
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(size, size);
    a(0, 0) = 1.0;
    for (int h = 1; h <= order; ++h) {
      const double c = std::cos(sign * h * step), s = std::sin(sign * h * step);
      a(2 * h - 1, 2 * h - 1) = c;  // cos(h (gamma + step)) = cos cos - sin sin
      a(2 * h - 1, 2 * h) = -s;
      a(2 * h, 2 * h - 1) = s;  // sin(h (gamma + step)) = sin cos + cos sin
      a(2 * h, 2 * h) = c;
    }
    if (options.linear_drift) {
      a(harmonics, harmonics) = 1.0;
      a(harmonics, 0) = sign * alpha;
    }
    return a;
  };
  out.step = step_matrix(1.0);
  out.back = step_matrix(-1.0);
  out.first = basis_at(g0, -0.5);
  out.last = basis_at(g0 + (n - 1.0) * step, alpha * (n - 1.0) - 0.5);
  const Eigen::MatrixXd normal = recurrence_sums(out.step, out.first, d.samples).gram;
  const double t_mid = alpha * 0.5 * (n - 1.0) - 0.5;
  Eigen::MatrixXd b(size, ng);
  for (Eigen::Index k = 0; k < ng; ++k) b.col(k) = basis_at(d.gammas_rad[static_cast<std::size_t>(k)], t_mid);
  out.coefficients = normal.ldlt().solve(b);
  return out;
}

/// A stationary kernel in state-space form: cov(y_k, y_l) = h' Phi^|k-l| u (u = P h, P the state's stationary
/// covariance). A Gauss-Markov process: Phi = rho = e^{-dt/T}, u = its variance, h = 1; one seen through the
/// output lag: its two states (process, lagged output).
struct StateKernel {
  Eigen::MatrixXd phi;
  Eigen::VectorXd u, h;
};

/// The noise's covariance between two samples k, l of the record as a sum of kernels: state-space kernels,
/// w min(k, l) (the rate random walk from the record's start) and a constant.
struct NoiseKernels {
  std::vector<StateKernel> states;
  double walk = 0.0;
  double constant = 0.0;
};

/// The noise of `noise` beyond the white rate noise's own (unlagged) term, as kernels over the record's
/// samples (docs/noise.md, "Coloured noise in the prediction"), and the white variance per sample to add
/// (negative where the lag replaces the white term by its lagged kernel). The lag's start-up (y_0 = v_0) is
/// left out: its terms are e^{-t/T_lag} at a dwell's start t.
NoiseKernels coloured_kernels(const GyroNoise& noise, double sample_rate_hz, double* extra_white) {
  NoiseKernels k;
  const double dt = 1.0 / sample_rate_hz;
  const double white = std::pow(white_noise_sample_std_deg_h(noise, sample_rate_hz), 2);
  const double quantization = noise.quantization_deg_h * noise.quantization_deg_h / 12.0;
  const double walk_step = rate_random_walk_step_std_deg_h(noise.rate_random_walk_deg_h_rt_h, sample_rate_hz);
  const double s2 = walk_step * walk_step, b2 = noise.bias_instability_deg_h * noise.bias_instability_deg_h;
  const bool lag = noise.output_lag_s > 0.0;
  // The lag y_k = lambda y_{k-1} + (1 - lambda) v_k; 1 - lambda, 1 - lambda rho without cancellation.
  const double lambda = lag ? std::exp(-dt / noise.output_lag_s) : 0.0;
  const double one_minus_lambda = lag ? -std::expm1(-dt / noise.output_lag_s) : 1.0;
  // Quantization after the lag: white, q^2 / 12 per sample (the output spans many steps between samples).
  *extra_white = quantization;
  const auto one = [](double v) { return Eigen::VectorXd::Constant(1, v); };
  if (lag && white > 0.0) {
    // White noise through the lag: a Gauss-Markov process of decay lambda, variance sigma^2 (1-l)/(1+l).
    *extra_white -= white;
    k.states.push_back(
        {Eigen::MatrixXd::Constant(1, 1, lambda), one(white * one_minus_lambda / (1.0 + lambda)), one(1.0)});
  }
  if (b2 > 0.0)
    for (std::size_t p = 0; p < kBiasInstabilityProcesses; ++p) {
      const double tp = kBiasInstabilityCorrelationTimesS[p], var = b2 * kBiasInstabilityVarianceWeights[p];
      const double rho = std::exp(-dt / tp);
      if (!lag) {
        k.states.push_back({Eigen::MatrixXd::Constant(1, 1, rho), one(var), one(1.0)});
        continue;
      }
      // States (x, y): x_{k+1} = rho x_k + w_k, y_{k+1} = lambda y_k + (1 - lambda) x_{k+1}. Stationary:
      // var x = var, cov(x, y) = var (1-l)/(1 - l rho), var y = var (1-l)(1 + l rho)/((1+l)(1 - l rho)).
      const double one_minus_lambda_rho = -std::expm1(-dt / noise.output_lag_s - dt / tp);
      Eigen::MatrixXd phi(2, 2);
      phi << rho, 0.0, one_minus_lambda * rho, lambda;
      Eigen::VectorXd u(2), h(2);
      u << var * one_minus_lambda / one_minus_lambda_rho,
          var * one_minus_lambda * (1.0 + lambda * rho) / ((1.0 + lambda) * one_minus_lambda_rho);
      h << 0.0, 1.0;
      k.states.push_back({phi, u, h});
    }
  if (s2 > 0.0) {
    k.walk = s2;
    if (lag) {
      // y_k = s sum_{m<k} n_m (1 - lambda^(k-m)): cov = s^2 [min(k, l) - l/(1-l) - l/(1-l^2) lambda^|k-l|].
      k.constant = -s2 * lambda / one_minus_lambda;
      k.states.push_back({Eigen::MatrixXd::Constant(1, 1, lambda),
                          one(-s2 * lambda / (one_minus_lambda * (1.0 + lambda))), one(1.0)});
    }
  }
  return k;
}

}  // namespace

Eigen::MatrixXd coloured_noise_position_covariance(const Reduction& r, const ReduceOptions& options,
                                                   const GyroNoise& noise, double sample_rate_hz,
                                                   bool* complete) {
  const auto np = static_cast<Eigen::Index>(r.positions.size());
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(np, np);
  if (complete) *complete = true;
  double extra_white = 0.0;
  const NoiseKernels kernels = coloured_kernels(noise, sample_rate_hz, &extra_white);
  if (kernels.states.empty() && kernels.walk == 0.0 && extra_white == 0.0) return cov;
  // Each kernel's sums over a dwell's samples come from linear recurrences over them, summed by doubling:
  // a cost of O(log N) per dwell, not O(N) (docs/noise.md, docs/performance.md).
  const std::size_t nd = r.dwells.size();
  std::vector<std::optional<DwellBasis>> basis(nd);
  for (std::size_t d = 0; d < nd; ++d) {
    basis[d] = dwell_basis(r.dwells[d], options, sample_rate_hz);
    if (!basis[d] && complete) *complete = false;
  }
  // Dwell-level covariance blocks (ng_d x ng_e), then scattered to the positions.
  std::vector<std::vector<Eigen::MatrixXd>> block(nd, std::vector<Eigen::MatrixXd>(nd));
  for (std::size_t d = 0; d < nd; ++d)
    for (std::size_t e = 0; e < nd; ++e)
      if (basis[d] && basis[e])
        block[d][e] = Eigen::MatrixXd::Zero(basis[d]->coefficients.cols(), basis[e]->coefficients.cols());
  // Each pair of dwells once, the earlier first; the samples from the last of d to the first of e.
  const auto gap = [&](std::size_t d, std::size_t e) -> std::optional<std::uint64_t> {
    if (d == e || !basis[d] || !basis[e] || !(r.dwells[d].last_time_s < r.dwells[e].first_time_s))
      return std::nullopt;
    return static_cast<std::uint64_t>(basis[e]->first_index - basis[d]->first_index) - basis[d]->samples + 1;
  };

  // Extra white noise (quantization; minus the white term where the lag colours it): within a dwell only.
  if (extra_white != 0.0)
    for (std::size_t d = 0; d < nd; ++d)
      if (basis[d]) block[d][d] += extra_white * dwell_white_noise_covariance(r.dwells[d], options);

  // A state-space kernel h' Phi^|i-j| u. Within a dwell: with F_i = sum_{j<=i} Phi^(i-j) u x_j' (r x s),
  // sum_ij x_i x_j' K(i-j) = W + W' - K(0) M, W = sum_i x_i (h' F_i); the state (x_i, vec F_i) advances by
  // [[A, 0], [A (x) u, I (x) Phi]]. Across dwells d before e, K factorises at the gap g:
  // (sum_i a_gi Phi^(N-1-i) u)' Phi^g' (sum_j a_hj Phi^j' h), the left from F_{N-1}, the right a sum of the
  // recurrence x_j (x) Phi^j' h.
  for (const StateKernel& k : kernels.states) {
    const Eigen::Index rs = k.phi.rows();
    std::vector<Eigen::MatrixXd> left(nd), right(nd);  // r x ng each
    for (std::size_t d = 0; d < nd; ++d) {
      if (!basis[d]) continue;
      const DwellBasis& b = *basis[d];
      const Eigen::Index s = b.step.rows();
      Eigen::MatrixXd step = Eigen::MatrixXd::Zero(s + rs * s, s + rs * s);
      step.topLeftCorner(s, s) = b.step;
      step.bottomLeftCorner(rs * s, s) = kron(b.step, k.u);
      step.bottomRightCorner(rs * s, rs * s) = kron(Eigen::MatrixXd::Identity(s, s), k.phi);
      Eigen::VectorXd z0(s + rs * s);
      z0 << b.first, kron(b.first, k.u);
      const RecurrenceSums f = recurrence_sums(step, z0, b.samples);
      const Eigen::MatrixXd w = f.gram.block(0, s, s, rs * s) * kron(Eigen::MatrixXd::Identity(s, s), k.h);
      const Eigen::MatrixXd q = w + w.transpose() - k.h.dot(k.u) * f.gram.topLeftCorner(s, s);
      block[d][d] += b.coefficients.transpose() * q * b.coefficients;
      const Eigen::Map<const Eigen::MatrixXd> last_f(f.last.data() + s, rs, s);
      left[d] = last_f * b.coefficients;
      const RecurrenceSums g =
          recurrence_sums(kron(b.step, k.phi.transpose()), kron(b.first, k.h), b.samples);
      right[d] = Eigen::Map<const Eigen::MatrixXd>(g.sum.data(), rs, s) * b.coefficients;
    }
    for (std::size_t d = 0; d < nd; ++d)
      for (std::size_t e = 0; e < nd; ++e)
        if (const auto g = gap(d, e)) {
          const Eigen::MatrixXd c = left[d].transpose() * matrix_power(k.phi, *g).transpose() * right[e];
          block[d][e] += c;
          block[e][d] += c.transpose();
        }
  }

  // Rate random walk: r_k = s sum_{m<k} n_m from the record's start, cov(r_k, r_l) = s^2 min(k, l) (w below).
  // Within a dwell starting at sample k0: k0 (sum a_g)(sum a_h) + sum_{m>=1} S_g(m) S_h(m), S(m) = sum_{i>=m}
  // a_i; the tail sums of the basis S(m) = x_m + S(m+1) by the backward recurrence (x_m, S(m)) from m = N-1,
  // [[A^-1, 0], [A^-1, I]], whose sum over m >= 1 is also sum_i i x_i. Across dwells (d before e):
  // w (sum_i a_gi k_i)(sum_j a_hj). A constant kernel (the lag's) reaches every pair through sum a.
  if (kernels.walk != 0.0 || kernels.constant != 0.0) {
    std::vector<Eigen::VectorXd> sums(nd), index_moments(nd);
    for (std::size_t d = 0; d < nd; ++d) {
      if (!basis[d]) continue;
      const DwellBasis& b = *basis[d];
      const Eigen::Index s = b.step.rows();
      Eigen::MatrixXd step = Eigen::MatrixXd::Zero(2 * s, 2 * s);
      step.topLeftCorner(s, s) = b.back;
      step.bottomLeftCorner(s, s) = b.back;
      step.bottomRightCorner(s, s) = Eigen::MatrixXd::Identity(s, s);
      Eigen::VectorXd z0(2 * s);
      z0 << b.last, b.last;
      const RecurrenceSums tails = recurrence_sums(step, z0, b.samples - 1);
      const Eigen::VectorXd total = b.first + tails.last.tail(s);  // S(0) = x_0 + S(1)
      sums[d] = b.coefficients.transpose() * total;
      index_moments[d] = b.coefficients.transpose() * (b.first_index * total + tails.sum.tail(s));
      const Eigen::MatrixXd inner =
          b.coefficients.transpose() * tails.gram.bottomRightCorner(s, s) * b.coefficients;
      block[d][d] += kernels.walk * (b.first_index * sums[d] * sums[d].transpose() + inner) +
                     kernels.constant * sums[d] * sums[d].transpose();
    }
    for (std::size_t d = 0; d < nd; ++d)
      for (std::size_t e = 0; e < nd; ++e)
        if (gap(d, e)) {
          const Eigen::MatrixXd c = kernels.walk * index_moments[d] * sums[e].transpose() +
                                    kernels.constant * sums[d] * sums[e].transpose();
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
    d.output.covariance = Eigen::MatrixXd::Zero(ng, ng);
  }
  for (std::size_t i = 0; i < r.positions.size(); ++i) {
    ReducedPosition& a = r.positions[i];
    a.std_err = std::sqrt(cov(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)));
    for (std::size_t j = 0; j < r.positions.size(); ++j) {
      const ReducedPosition& b = r.positions[j];
      if (a.dwell == b.dwell)
        r.dwells[static_cast<std::size_t>(a.dwell)].output.covariance(a.gamma_slot, b.gamma_slot) =
            cov(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
    }
  }
  for (Dwell& d : r.dwells)
    for (std::size_t k = 0; k < d.gammas_rad.size(); ++k)
      d.output.std_err[k] =
          std::sqrt(d.output.covariance(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(k)));
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
                       const std::vector<PositionModelTerms>& model_terms, const CentrifugeModel& model,
                       const CalibrationOptions& options, const Eigen::MatrixXd& covariance) {
  const auto np = static_cast<Eigen::Index>(r.positions.size());
  // The estimates: the coefficients, then the combinations, then the closed form's alternatives.
  std::vector<double*> stds;
  std::vector<double> base;
  std::vector<std::function<double(const CalibrationResult&)>> value_of;
  // The sensor's coefficients (the gyro's dF .. dOS and with drift+rate its rate errors, an accelerometer's
  // K0 .. delta_o).
  for (std::size_t c = 0; c < result.coefficients.size(); ++c)
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
  // The gain of each estimate on each position's value, by a step of `step` in that value: 1 deg/h for the
  // gyro's (its estimates are linear in the values); for an accelerometer, whose coefficients are ratios of
  // its products (Kx = u_x / K1), a step of 1e-4 output units, small enough that the derivative's error
  // (relative, of the step's order over a value of ~1 g) is far below a std's own precision.
  const double step = result.sensor == SensorKind::kGyro ? 1.0 : 1e-4;
  Eigen::MatrixXd gain(static_cast<Eigen::Index>(stds.size()), np);
  for (Eigen::Index k = 0; k < np; ++k) {
    Reduction shifted = r;
    shifted.positions[static_cast<std::size_t>(k)].mean += step;
    const CalibrationResult e = identify(shifted, model_terms, model, options);
    for (std::size_t i = 0; i < stds.size(); ++i)
      gain(static_cast<Eigen::Index>(i), k) = (value_of[i](e) - base[i]) / step;
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
  const SensorChannel channel = s.channels().front();
  const Sensor& sensor = channel.sensor;
  const std::vector<PositionModelTerms> model_terms =
      reduce_sensor_model_terms(r, model, options.reduce, channel);
  const Accelerometer& a = std::get<Accelerometer>(sensor);
  const Eigen::VectorXd u = a.products();
  for (std::size_t i = 0; i < r.positions.size(); ++i)
    r.positions[i].mean = design_output(model_terms[i].sensor_exact, u);
  // The noise as the simulator draws it, in output units (analysis/estimates.hpp output_noise); its
  // covariance through the reduction in closed form as the gyro's (coloured_noise_position_covariance).
  const GyroNoise noise = output_noise(s);
  set_predicted_std_errors(r, noise, s.test.sample_rate_hz, options.reduce);
  CalibrationOptions identify_options = options;
  identify_options.least_squares.chi2_warning_sigma = std::numeric_limits<double>::infinity();
  CalibrationResult result = identify(r, model_terms, model, identify_options);
  if (a.noise.bias_instability_ug > 0.0 || a.noise.quantization_ug > 0.0) {
    // The noise correlated across positions (the bias instability's), as the gyro's plan counts it: each
    // estimate's variance g' C g over every position's covariance C.
    bool complete = true;
    const Eigen::MatrixXd covariance =
        predicted_noise_position_covariance(r, options.reduce, noise, s.test.sample_rate_hz, &complete);
    count_whole_noise(result, r, model_terms, model, identify_options, covariance);
    if (!complete)
      result.warnings.push_back(
          "the predicted uncertainties leave out the bias instability and quantization of the dwells reduced "
          "by the window mean; they add to them.");
  }
  if (a.noise.velocity_random_walk_ug_rt_hz == 0.0 && a.noise.bias_instability_ug == 0.0 &&
      a.noise.quantization_ug == 0.0)
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
  const std::vector<PositionModelTerms> model_terms =
      reduce_model_terms(r, model, options.reduce, kMaxModelSamplesPerDwell);
  set_noise_free_outputs(r, model_terms, s.gyro, s.gyro_rate);
  set_predicted_std_errors(r, s.noise, s.test.sample_rate_hz, options.reduce);
  // The predicted outputs are noise-free, so chi2 is ~0 by construction: its test against the degrees of
  // freedom says nothing about a plan and must not warn.
  CalibrationOptions identify_options = options;
  identify_options.least_squares.chi2_warning_sigma = std::numeric_limits<double>::infinity();
  // A self-calibration's Jacobian evaluated on the same bounded samples as the model terms.
  identify_options.max_model_samples_per_dwell = kMaxModelSamplesPerDwell;
  CalibrationResult result = identify(r, model_terms, model, identify_options);
  // The Allan variances compared at the longest dwell's duration: where the colored noise dominates,
  // averaging longer stops paying (issue 10, item 2).
  double longest_dwell_s = 0.0;
  for (const Dwell& d : r.dwells) longest_dwell_s = std::max(longest_dwell_s, d.planned_duration_s);
  if (std::string w = dominant_noise_warning(s.noise, longest_dwell_s); !w.empty())
    result.warnings.push_back(std::move(w));
  if (s.noise.bias_instability_deg_h > 0 || s.noise.rate_random_walk_deg_h_rt_h > 0 ||
      s.noise.quantization_deg_h > 0 || s.noise.output_lag_s > 0) {
    bool complete = true;
    const Eigen::MatrixXd covariance =
        predicted_noise_position_covariance(r, options.reduce, s.noise, s.test.sample_rate_hz, &complete);
    count_whole_noise(result, r, model_terms, model, identify_options, covariance);
    if (!complete)
      result.warnings.push_back(
          "the predicted uncertainties leave out the bias instability, rate random walk, quantization and "
          "output lag of the dwells reduced by the window mean; they add to them.");
    // Quantization counts as white noise of q^2/12 a sample: right where the output moves by more than a step
    // between samples (the white noise dithers it), not where it stays within one.
    const double white_std = white_noise_sample_std_deg_h(s.noise, s.test.sample_rate_hz);
    if (s.noise.quantization_deg_h > 0 && white_std < 0.5 * s.noise.quantization_deg_h)
      result.warnings.push_back(fmt::format(
          "[gyro.noise] quantization_deg_h = {:.3g} is more than twice the white noise's {:.3g} deg/h a "
          "sample: the rounding error is then not white noise of q^2/12 a sample, as the predicted "
          "uncertainties count it, but follows the signal.",
          s.noise.quantization_deg_h, white_std));
    // The lag's start-up (y_0 = v_0) is left out of the prediction: terms e^{-t/T_lag} at a dwell's start t.
    double first_start_s = std::numeric_limits<double>::infinity();
    for (const Dwell& d : r.dwells) first_start_s = std::min(first_start_s, d.first_time_s);
    if (s.noise.output_lag_s > 0 && first_start_s < 23.0 * s.noise.output_lag_s)
      result.warnings.push_back(fmt::format(
          "the first dwell starts {:.3g} s after the record's start, within 23 output lags ([gyro.noise] "
          "output_lag_s = {:.3g}): the lag's start-up, left out of the predicted uncertainties, reaches its "
          "values by up to e^(-t/T) = {:.2g}.",
          first_start_s, s.noise.output_lag_s, std::exp(-first_start_s / s.noise.output_lag_s)));
  } else if (s.noise.angle_random_walk_deg_rt_h == 0) {
    result.warnings.push_back("the configured gyro noise is zero: the predicted uncertainties are zero.");
  }
  return result;
}

}  // namespace gyrocal
