#include "gyrocal/reduce/dwell_reduction.hpp"

#include <cmath>
#include <limits>

#include <Eigen/Cholesky>

#include "gyrocal/core/units.hpp"
#include "gyrocal/reduce/dwell_accumulator.hpp"

namespace gyrocal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A diagonal covariance from per-gamma gains: operators whose values share no sample.
Eigen::MatrixXd diagonal_of(const std::vector<double>& gain) {
  const auto ng = static_cast<Eigen::Index>(gain.size());
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(ng, ng);
  for (Eigen::Index k = 0; k < ng; ++k) cov(k, k) = gain[static_cast<std::size_t>(k)];
  return cov;
}

}  // namespace

void harmonic_basis(double gamma_rad, int order, double* out) {
  harmonic_basis(std::cos(gamma_rad), std::sin(gamma_rad), order, out);
}

void harmonic_basis(double c1, double s1, int order, double* out) {
  out[0] = 1.0;
  double c = 1.0, s = 0.0;
  for (int k = 1; k <= order; ++k) {
    const double cn = c * c1 - s * s1;
    s = s * c1 + c * s1;
    c = cn;
    out[2 * k - 1] = c;
    out[2 * k] = s;
  }
}

namespace {

template <int N>
void add_outer_fixed(double* __restrict normal, const double* __restrict b) {
  for (int j = 0; j < N; ++j) {
    const double bj = b[j];
    for (int i = j; i < N; ++i) normal[i + j * N] += b[i] * bj;
  }
}

}  // namespace

void add_outer_product(double* normal, const double* b, int n) {
  switch (n) {
    case 7:
      return add_outer_fixed<7>(normal, b);
    case 8:
      return add_outer_fixed<8>(normal, b);
    case 10:
      return add_outer_fixed<10>(normal, b);
    default:
      for (int j = 0; j < n; ++j) {
        const double bj = b[j];
        for (int i = j; i < n; ++i) normal[i + j * n] += b[i] * bj;
      }
  }
}

void HarmonicMoments::lower(double* out) const {
  const int p = 2 * order_ + 2;
  // Sums of cos k g and sin k g for any integer k: cos is even, sin odd, and k = 0 counts the samples.
  const auto sum_cos = [&](int k) { return k == 0 ? count_ : cos_[k < 0 ? -k : k]; };
  const auto sum_sin = [&](int k) { return k == 0 ? 0.0 : k < 0 ? -sin_[-k] : sin_[k]; };
  // Term i of the basis: 0 the constant, 2k - 1 cos k g, 2k sin k g, p - 1 the time.
  for (int j = 0; j < p; ++j) {
    for (int i = j; i < p; ++i) {
      double v = 0.0;
      if (i == p - 1) {
        const int b = (j + 1) / 2;  // the harmonic of term j
        v = j == p - 1 ? tt_ : j == 0 ? t_ : j % 2 == 1 ? t_cos_[b] : t_sin_[b];
      } else if (j == 0) {
        const int a = (i + 1) / 2;
        v = i == 0 ? count_ : i % 2 == 1 ? cos_[a] : sin_[a];
      } else {
        const int a = (i + 1) / 2, b = (j + 1) / 2;
        const bool cos_a = i % 2 == 1, cos_b = j % 2 == 1;
        if (cos_a && cos_b)
          v = 0.5 * (sum_cos(a - b) + sum_cos(a + b));
        else if (!cos_a && !cos_b)
          v = 0.5 * (sum_cos(a - b) - sum_cos(a + b));
        else if (!cos_a && cos_b)  // sin a cos b
          v = 0.5 * (sum_sin(a + b) + sum_sin(a - b));
        else  // cos a sin b
          v = 0.5 * (sum_sin(a + b) - sum_sin(a - b));
      }
      out[i + j * p] = v;
    }
  }
}

// ---- RevolutionSums ---------------------------------------------------------------------------------------

void RevolutionSums::add(double ti, const Eigen::VectorXd& vi) {
  periods.push_back({index, ti, vi});
  if (v.size() == 0) {
    v0 = vi;
    v = tv = Eigen::VectorXd::Zero(vi.size());
    vv = Eigen::MatrixXd::Zero(vi.size(), vi.size());
  }
  const Eigen::VectorXd d = vi - v0;
  if (sweep != 0.0) {
    if (bb.size() == 0) {
      bb = Eigen::MatrixXd::Zero(4, 4);
      bv = Eigen::MatrixXd::Zero(4, vi.size());
    }
    const Eigen::Vector4d b(1.0, ti, std::cos(sweep * (ti + 0.5)), std::sin(sweep * (ti + 0.5)));
    bb += b * b.transpose();
    bv += b * d.transpose();
  }
  n += 1;
  t += ti;
  tt += ti * ti;
  v += d;
  tv += ti * d;
  vv += d * d.transpose();
}

Eigen::MatrixXd RevolutionSums::covariance_at(double t_mid, bool drift) const {
  // Residual cross products of straight-line fits in time (deviations from the means without drift),
  // divided by the degrees of freedom, times the variance factor of the line's value at t_mid.
  const double dof = n - parameters(drift);
  if (v.size() == 0 || dof < 1.0) return Eigen::MatrixXd::Constant(v.size(), v.size(), kNaN);
  if (sweep != 0.0) {
    // The same with the sweep's cos and sin beside the mean (and drift): a general linear fit in time.
    std::vector<Eigen::Index> keep = {0};
    if (drift) keep.push_back(1);
    keep.push_back(2);
    keep.push_back(3);
    const auto p = static_cast<Eigen::Index>(keep.size());
    Eigen::MatrixXd a(p, p), r(p, v.size());
    Eigen::VectorXd b_mid(p);
    const Eigen::Vector4d mid(1.0, t_mid, std::cos(sweep * (t_mid + 0.5)), std::sin(sweep * (t_mid + 0.5)));
    for (Eigen::Index i = 0; i < p; ++i) {
      const Eigen::Index ki = keep[static_cast<std::size_t>(i)];
      for (Eigen::Index j = 0; j < p; ++j) a(i, j) = bb(ki, keep[static_cast<std::size_t>(j)]);
      r.row(i) = bv.row(ki);
      b_mid[i] = mid[ki];
    }
    const auto ldlt = a.ldlt();
    const Eigen::MatrixXd residual = vv - r.transpose() * ldlt.solve(r);
    // The scatter is measured about the fit with the sweep; the values it is the level of are the plain
    // fit's (without the sweep's terms), whose variance factor is that of the mean and drift alone.
    const Eigen::Index q = drift ? 2 : 1;
    const Eigen::MatrixXd plain = a.topLeftCorner(q, q);
    const Eigen::VectorXd b_plain = b_mid.head(q);
    const Eigen::MatrixXd c = residual / dof * b_plain.dot(plain.ldlt().solve(b_plain));
    return 0.5 * (c + c.transpose());
  }
  const double tbar = t / n;
  const Eigen::VectorXd vbar = v / n;
  const double stt = tt - n * tbar * tbar;
  const Eigen::MatrixXd svv = vv - n * vbar * vbar.transpose();
  const Eigen::VectorXd stv = tv - n * tbar * vbar;
  const bool line = drift && stt > 0;
  const Eigen::MatrixXd residual = line ? Eigen::MatrixXd(svv - stv * stv.transpose() / stt) : svv;
  const double lever = line ? (t_mid - tbar) * (t_mid - tbar) / stt : 0.0;
  const Eigen::MatrixXd c = residual / dof * (1.0 / n + lever);
  return 0.5 * (c + c.transpose());
}

// ---- StaticMean -------------------------------------------------------------------------------------------

StaticMean::StaticMean(std::size_t gammas, int columns, bool with_periods)
    : gammas_(gammas), with_periods_(with_periods), sum_(Eigen::VectorXd::Zero(columns)) {}

void StaticMean::add(double /*t_scaled*/, double /*gamma_rad*/, const double* values) {
  ++samples_;
  for (Eigen::Index c = 0; c < sum_.size(); ++c) sum_[c] += values[c];
  if (!with_periods_) return;
  batch_sum_ += values[0];
  ++batch_n_;
}

void StaticMean::add_sums(std::size_t samples, const Eigen::MatrixXd& rhs) {
  samples_ += samples;
  sum_ += rhs.row(0).transpose();
}

void StaticMean::close_period(RevolutionSums& scatter) {
  // A batch's mean enters at time 0: the scatter of a hold is about the batches' mean (fits_drift: never).
  if (batch_n_ > 0)
    scatter.add(0.0, Eigen::VectorXd::Constant(1, batch_sum_ / static_cast<double>(batch_n_)));
  discard_period();
}

void StaticMean::discard_period() {
  batch_sum_ = 0.0;
  batch_n_ = 0;
}

void StaticMean::values(int column, double /*t_mid*/, DwellValues& out) const {
  if (samples_ == 0 || out.value.empty()) return;
  out.value[0] = sum_[column] / static_cast<double>(samples_);
  out.samples[0] = samples_;
}

std::vector<double> StaticMean::white_noise_gain(double /*t_mid*/) const {
  std::vector<double> gain(gammas_, kNaN);
  if (samples_ > 0 && gammas_ > 0) gain[0] = 1.0 / static_cast<double>(samples_);
  return gain;
}

Eigen::MatrixXd StaticMean::white_noise_covariance(double t_mid) const {
  return diagonal_of(white_noise_gain(t_mid));
}

// ---- HarmonicFit ------------------------------------------------------------------------------------------

HarmonicFit::HarmonicFit(std::vector<double> gammas_rad, int order, bool linear_drift, int columns,
                         bool with_periods)
    : gammas_(std::move(gammas_rad)),
      order_(order),
      drift_(linear_drift),
      columns_(columns),
      with_periods_(with_periods) {
  const int n = basis_size();
  normal_ = Eigen::MatrixXd::Zero(n, n);
  rhs_ = Eigen::MatrixXd::Zero(n, columns_);
  if (with_periods_) {
    period_normal_ = Eigen::MatrixXd::Zero(n, n);
    period_rhs_ = Eigen::MatrixXd::Zero(n, columns_);
  }
}

Eigen::MatrixXd HarmonicFit::total_normal() const {
  if (!with_periods_) return normal_;
  return normal_ + period_normal_;
}

Eigen::MatrixXd HarmonicFit::total_rhs() const {
  if (!with_periods_) return rhs_;
  return rhs_ + period_rhs_;
}

void HarmonicFit::fold_period() {
  if (!with_periods_) return;
  normal_ += period_normal_;
  rhs_ += period_rhs_;
  period_normal_.setZero();
  period_rhs_.setZero();
}

void HarmonicFit::basis(double gamma_rad, double t_scaled, double* out) const {
  harmonic_basis(gamma_rad, order_, out);
  if (drift_) out[2 * order_ + 1] = t_scaled;
}

void HarmonicFit::add(double t_scaled, double gamma_rad, const double* values) {
  double b[32];
  basis(gamma_rad, t_scaled, b);
  add_basis(t_scaled, b, values);
}

void HarmonicFit::add_basis(double t_scaled, const double* b, const double* values) {
  ++samples_;
  // The hot loop of a calibration: raw column-major storage, lower triangles only.
  const int n = basis_size();
  add_outer_product(with_periods_ ? period_normal_.data() : normal_.data(), b, n);
  double* __restrict rhs = with_periods_ ? period_rhs_.data() : rhs_.data();
  for (int c = 0; c < columns_; ++c) {
    const double v = values[c];
    for (int i = 0; i < n; ++i) rhs[i + c * n] += b[i] * v;
  }
  if (!with_periods_) return;
  ++rev_samples_;
  rev_time_sum_ += t_scaled;
}

void HarmonicFit::add_run(std::size_t samples, double t_scaled_sum, const double* lower, const double* rhs) {
  const int n = basis_size();
  samples_ += samples;
  double* normal = with_periods_ ? period_normal_.data() : normal_.data();
  for (int j = 0; j < n; ++j)
    for (int i = j; i < n; ++i) normal[i + j * n] += lower[i + j * n];
  double* own_rhs = with_periods_ ? period_rhs_.data() : rhs_.data();
  for (int i = 0; i < n * columns_; ++i) own_rhs[i] += rhs[i];
  if (!with_periods_) return;
  rev_samples_ += samples;
  rev_time_sum_ += t_scaled_sum;
}

void HarmonicFit::add_sums(std::size_t samples, const Eigen::MatrixXd& normal, const Eigen::MatrixXd& rhs) {
  samples_ += samples;
  normal_.triangularView<Eigen::Lower>() += normal;
  rhs_ += rhs;
}

void HarmonicFit::close_period(RevolutionSums& scatter) {
  const int nr = 2 * order_ + 1;
  if (rev_samples_ >= static_cast<std::size_t>(2 * nr)) {
    const Eigen::MatrixXd full = period_normal_.topLeftCorner(nr, nr).selfadjointView<Eigen::Lower>();
    const Eigen::VectorXd x = full.ldlt().solve(period_rhs_.col(0).head(nr));
    const double t_mean = rev_time_sum_ / static_cast<double>(rev_samples_);
    Eigen::VectorXd values(static_cast<Eigen::Index>(gammas_.size()));
    for (std::size_t k = 0; k < gammas_.size(); ++k) {
      double b[32];
      basis(gammas_[k], 0.0, b);
      double v = 0.0;
      for (int i = 0; i < nr; ++i) v += b[i] * x[i];
      values[static_cast<Eigen::Index>(k)] = v;
    }
    scatter.add(t_mean, values);
  }
  discard_period();
}

void HarmonicFit::discard_period() {
  fold_period();
  rev_samples_ = 0;
  rev_time_sum_ = 0.0;
}

void HarmonicFit::values(int column, double t_mid, DwellValues& out) const {
  if (samples_ == 0) return;
  const Eigen::MatrixXd full = total_normal().selfadjointView<Eigen::Lower>();
  const Eigen::VectorXd x = full.ldlt().solve(total_rhs().col(column));
  const int n = basis_size();
  for (std::size_t k = 0; k < gammas_.size(); ++k) {
    double b[32];
    basis(gammas_[k], t_mid, b);
    double v = 0.0;
    for (int i = 0; i < n; ++i) v += b[i] * x[i];
    out.value[k] = v;
    out.samples[k] = samples_;
  }
}

std::vector<double> HarmonicFit::white_noise_gain(double t_mid) const {
  std::vector<double> gain(gammas_.size(), kNaN);
  if (samples_ == 0) return gain;
  const Eigen::MatrixXd full = total_normal().selfadjointView<Eigen::Lower>();
  const auto ldlt = full.ldlt();
  const int n = basis_size();
  for (std::size_t k = 0; k < gammas_.size(); ++k) {
    Eigen::VectorXd b(n);
    basis(gammas_[k], t_mid, b.data());
    gain[k] = b.dot(ldlt.solve(b));
  }
  return gain;
}

Eigen::MatrixXd HarmonicFit::white_noise_covariance(double t_mid) const {
  if (samples_ == 0) return diagonal_of(white_noise_gain(t_mid));
  const auto ng = static_cast<Eigen::Index>(gammas_.size());
  const Eigen::MatrixXd full = total_normal().selfadjointView<Eigen::Lower>();
  Eigen::MatrixXd b(basis_size(), ng);
  for (Eigen::Index k = 0; k < ng; ++k) basis(gammas_[static_cast<std::size_t>(k)], t_mid, b.col(k).data());
  return b.transpose() * full.ldlt().solve(b);
}

// ---- WindowMean -------------------------------------------------------------------------------------------

WindowMean::WindowMean(std::vector<double> gammas_rad, double window_deg, bool linear_drift, int columns,
                       bool with_periods)
    : gammas_(std::move(gammas_rad)),
      half_width_rad_(0.5 * window_deg * kDegToRad),
      drift_(linear_drift),
      columns_(columns),
      with_periods_(with_periods) {
  const auto ng = static_cast<Eigen::Index>(gammas_.size());
  sum_ = Eigen::MatrixXd::Zero(ng, columns_);
  tsum_ = Eigen::MatrixXd::Zero(ng, columns_);
  n_ = t_ = tt_ = Eigen::VectorXd::Zero(ng);
  rev_sum_ = rev_n_ = rev_t_ = Eigen::VectorXd::Zero(ng);
}

void WindowMean::add(double t_scaled, double gamma_rad, const double* values) {
  ++samples_;
  for (std::size_t k = 0; k < gammas_.size(); ++k) {
    if (std::abs(wrap_rad(gamma_rad - gammas_[k])) > half_width_rad_) continue;
    const auto kk = static_cast<Eigen::Index>(k);
    for (int c = 0; c < columns_; ++c) {
      sum_(kk, c) += values[c];
      tsum_(kk, c) += t_scaled * values[c];
    }
    n_[kk] += 1;
    t_[kk] += t_scaled;
    tt_[kk] += t_scaled * t_scaled;
    if (with_periods_) {
      rev_sum_[kk] += values[0];
      rev_n_[kk] += 1;
      rev_t_[kk] += t_scaled;
    }
  }
}

void WindowMean::close_period(RevolutionSums& scatter) {
  // A revolution counts when it passed through every window.
  if ((rev_n_.array() > 0).all()) {
    const double t_mean = rev_t_.sum() / rev_n_.sum();
    scatter.add(t_mean, rev_sum_.cwiseQuotient(rev_n_));
  }
  discard_period();
}

void WindowMean::discard_period() {
  rev_sum_.setZero();
  rev_n_.setZero();
  rev_t_.setZero();
}

void WindowMean::values(int column, double t_mid, DwellValues& out) const {
  for (std::size_t k = 0; k < gammas_.size(); ++k) {
    const auto kk = static_cast<Eigen::Index>(k);
    const double nk = n_[kk];
    if (nk == 0) continue;
    const double mean = sum_(kk, column) / nk;
    double v = mean;
    if (drift_) {
      const double tbar = t_[kk] / nk;
      const double stt = tt_[kk] - nk * tbar * tbar;
      const double stv = tsum_(kk, column) - nk * tbar * mean;
      if (stt > 0) v = mean + stv / stt * (t_mid - tbar);
    }
    out.value[k] = v;
    out.samples[k] = static_cast<std::size_t>(nk);
  }
}

std::vector<double> WindowMean::white_noise_gain(double t_mid) const {
  std::vector<double> gain(gammas_.size(), kNaN);
  for (std::size_t k = 0; k < gammas_.size(); ++k) {
    const auto kk = static_cast<Eigen::Index>(k);
    const double nk = n_[kk];
    if (nk == 0) continue;
    double g = 1.0 / nk;
    if (drift_) {
      const double tbar = t_[kk] / nk, stt = tt_[kk] - nk * tbar * tbar;
      if (stt > 0) g += (t_mid - tbar) * (t_mid - tbar) / stt;
    }
    gain[k] = g;
  }
  return gain;
}

Eigen::MatrixXd WindowMean::white_noise_covariance(double t_mid) const {
  return diagonal_of(white_noise_gain(t_mid));
}

// ---- The factory ------------------------------------------------------------------------------------------

DwellReduction make_dwell_reduction(const ReduceOptions& options, std::vector<double> gammas_rad,
                                    bool is_static, int columns, bool with_periods) {
  if (is_static) return StaticMean(gammas_rad.size(), columns, with_periods);
  switch (options.method) {
    case ReduceOptions::Method::kHarmonicFit:
      return HarmonicFit(std::move(gammas_rad), options.harmonic_order, options.linear_drift, columns,
                         with_periods);
    case ReduceOptions::Method::kWindowMean:
      return WindowMean(std::move(gammas_rad), options.window_deg, options.linear_drift, columns,
                        with_periods);
  }
  return HarmonicFit(std::move(gammas_rad), options.harmonic_order, options.linear_drift, columns,
                     with_periods);
}

}  // namespace gyrocal
