#include "gyrocal/reduce/dwell_accumulator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>

#include "gyrocal/core/units.hpp"

namespace gyrocal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The median of v (the upper one for an even count); reorders v.
double median(std::vector<double>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// 1 / Phi^-1(3/4): the median absolute deviation of normal noise times this is its standard deviation.
constexpr double kMadToSigma = 1.482602218505602;

/// A block never holds more samples than this (a revolution of more samples is tested in parts): it bounds
/// the memory of the outlier rule to a few MB whatever the plan.
constexpr std::size_t kMaxBlockSamples = std::size_t{1} << 15;

}  // namespace

bool ReduceOptions::IsValid(std::string* error) const {
  const auto fail = [error](const char* message) {
    if (error) *error = message;
    return false;
  };
  if (harmonic_order < 0 || harmonic_order > 12) return fail("harmonic_order must be between 0 and 12");
  if (!(window_deg > 0.0 && window_deg < 90.0)) return fail("window_deg must be in (0, 90) degrees");
  if (!(beta_tolerance_deg > 0.0)) return fail("beta_tolerance_deg must be positive");
  if (!(rate_tolerance > 0.0 && rate_tolerance < 0.5)) return fail("rate_tolerance must be in (0, 0.5)");
  if (!(static_rate_tolerance_rad_s > 0.0)) return fail("static_rate_tolerance_rad_s must be positive");
  if (static_batches < 2) return fail("static_batches must be at least 2");
  if (!(window_s > 0.0 && window_s <= 60.0)) return fail("window_s must be in (0, 60] s");
  if (!(angle_tolerance_deg > 0.0 && angle_tolerance_deg < 90.0))
    return fail("angle_tolerance_deg must be in (0, 90) degrees");
  if (!(rate_steadiness > 0.0 && rate_steadiness < 0.5)) return fail("rate_steadiness must be in (0, 0.5)");
  if (!(gap_intervals > 1.0)) return fail("gap_intervals must be above 1");
  if (encoder_glitch_rows < 0 || encoder_glitch_rows > 1000)
    return fail("encoder_glitch_rows must be between 0 and 1000");
  if (!(leave_guard_s >= 0.0 && leave_guard_s <= 60.0)) return fail("leave_guard_s must be in [0, 60] s");
  if (max_stretches_per_dwell < 1) return fail("max_stretches_per_dwell must be at least 1");
  if (!(wander_warning_deg > 0.0)) return fail("wander_warning_deg must be positive");
  if (model_samples_per_revolution < 0 ||
      (model_samples_per_revolution > 0 && model_samples_per_revolution < 16))
    return fail("model_samples_per_revolution must be 0 (every sample) or at least 16");
  if (!(outlier_threshold == 0.0 || (outlier_threshold >= 3.0 && outlier_threshold <= 1e6)))
    return fail("outlier_threshold must be 0 (no rejection) or between 3 and 1e6 robust standard deviations");
  if (outlier_block_samples < 16 || outlier_block_samples > 4096)
    return fail("outlier_block_samples must be between 16 and 4096");
  return true;
}

DwellAccumulator::DwellAccumulator(const ReduceOptions& options, std::vector<double> gammas_rad,
                                   bool is_static, int columns, double planned_duration_s, bool with_std_err,
                                   double sweep_rate_rad_s)
    : options_(options),
      gammas_(std::move(gammas_rad)),
      static_(is_static),
      columns_(columns),
      duration_s_(planned_duration_s),
      with_std_err_(with_std_err),
      trend_() {
  // docs/physics.md section 15: the heading's sweep, spinning only (held, the platform does not turn).
  if (!static_ && sweep_rate_rad_s != 0.0) sweep_scaled_ = sweep_rate_rad_s * duration_s_;
  trend_.sweep = sweep_scaled_;
  robust_ = with_std_err_ && columns_ == 1 && options_.outlier_threshold > 0.0;
  if (robust_) {
    const int nd = detection_size();
    ref_normal_ = Eigen::MatrixXd::Zero(nd, nd);
    ref_rhs_ = Eigen::VectorXd::Zero(nd);
  }
  const int n = basis_size();
  const auto ng = static_cast<Eigen::Index>(gammas_.size());
  if (static_) {
    static_sum_ = Eigen::VectorXd::Zero(columns_);
  } else if (options_.method == ReduceOptions::Method::kHarmonicFit) {
    normal_ = Eigen::MatrixXd::Zero(n, n);
    rhs_ = Eigen::MatrixXd::Zero(n, columns_);
    const int nr = 2 * options_.harmonic_order + 1;
    rev_normal_ = Eigen::MatrixXd::Zero(nr, nr);
    rev_rhs_ = Eigen::VectorXd::Zero(nr);
  } else {
    window_sum_ = Eigen::MatrixXd::Zero(ng, columns_);
    window_tsum_ = Eigen::MatrixXd::Zero(ng, columns_);
    window_n_ = window_t_ = window_tt_ = Eigen::VectorXd::Zero(ng);
    rev_window_sum_ = rev_window_n_ = rev_window_t_ = Eigen::VectorXd::Zero(ng);
  }
}

int DwellAccumulator::basis_size() const {
  return 2 * options_.harmonic_order + 1 + (options_.linear_drift ? 1 : 0);
}

namespace {

// 1, cos g, sin g, ..., cos Ng, sin Ng into out[0 .. 2N]; cos kg, sin kg by angle addition.
void harmonic_basis(double gamma_rad, int order, double* out) {
  const double c1 = std::cos(gamma_rad), s1 = std::sin(gamma_rad);
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

}  // namespace

// The reduction's harmonic fit: harmonic_basis [, t_scaled].
void DwellAccumulator::basis(double gamma_rad, double t_scaled, double* out) const {
  harmonic_basis(gamma_rad, options_.harmonic_order, out);
  if (options_.linear_drift) out[2 * options_.harmonic_order + 1] = t_scaled;
}

int DwellAccumulator::detection_size() const {
  return static_ ? 2 : 2 * options_.harmonic_order + 2 + (sweep_scaled_ != 0.0 ? 2 : 0);
}

// The outlier rule's fit: harmonics and a linear drift (a static hold: mean and drift), whatever the
// reduction; and the heading's sweep at a counter rate offset (docs/physics.md section 15).
void DwellAccumulator::detection_basis(double gamma_rad, double t_scaled, double* out) const {
  if (static_) {
    out[0] = 1.0;
    out[1] = t_scaled;
    return;
  }
  harmonic_basis(gamma_rad, options_.harmonic_order, out);
  out[2 * options_.harmonic_order + 1] = t_scaled;
  if (sweep_scaled_ != 0.0) {
    out[2 * options_.harmonic_order + 2] = std::cos(sweep_scaled_ * (t_scaled + 0.5));
    out[2 * options_.harmonic_order + 3] = std::sin(sweep_scaled_ * (t_scaled + 0.5));
  }
}

void DwellAccumulator::add(double t, double gamma, const double* values) {
  if (samples_ == 0) {
    t_first_ = t;
    gamma_first_ = gamma;
  }
  t_last_ = t;
  gamma_last_ = gamma;
  ++samples_;
  if (!static_) seen_revolution_ = static_cast<int>(std::floor(std::abs(gamma - gamma_first_) / (2.0 * kPi)));
  const bool after_break = break_next_;
  break_next_ = false;
  if (!robust_) {
    accumulate(t, gamma, values, after_break);
    return;
  }
  // A block closes where a revolution begins (a static hold: anywhere) once it holds enough samples.
  const std::size_t block = static_cast<std::size_t>(options_.outlier_block_samples);
  const bool boundary = static_ || seen_revolution_ != block_revolution_;
  if ((boundary && pending_.size() >= block) || pending_.size() >= kMaxBlockSamples) test_block();
  block_revolution_ = seen_revolution_;
  pending_.push_back({t, gamma, values[0], after_break});
}

void DwellAccumulator::break_revolution() {
  if (samples_ > 0) break_next_ = true;
}

// docs/physics.md section 14: each sample's residual about the fit of the dwell so far and its block; beyond
// outlier_threshold robust standard deviations of the block's residuals it is an outlier, the fit is
// repeated without the outliers and the test with it, until the outliers do not change. Outliers are
// replaced by the final fit's value at their instant, so the reduction operator (which samples, which
// weights) stays the one the model's channels go through (docs/calibration.md, "Spikes").
void DwellAccumulator::test_block() {
  const std::size_t n = pending_.size();
  if (n == 0) return;
  const int p = detection_size();
  const auto pp = static_cast<std::size_t>(p);
  scratch_basis_.resize(n * pp);
  for (std::size_t i = 0; i < n; ++i)
    detection_basis(pending_[i].gamma, (pending_[i].t - t_first_) / duration_s_ - 0.5,
                    &scratch_basis_[i * pp]);
  const auto basis_of = [&](std::size_t i) { return &scratch_basis_[i * pp]; };
  const auto fit_at = [&](std::size_t i, const Eigen::VectorXd& x) {
    const double* b = basis_of(i);
    double v = 0.0;
    for (int k = 0; k < p; ++k) v += b[k] * x[k];
    return v;
  };

  std::vector<char> out(n, 0);
  std::vector<double> work;
  work.reserve(n);
  // Residuals below a part in 1e9 of the output are rounding, never outliers (a noise-free record).
  for (const Pending& s : pending_) work.push_back(std::abs(s.value));
  const double floor = 1e-9 * (1.0 + median(work));
  // A first screen on the raw values: a sample a thousand times further from the block's median than their
  // robust spread (which holds the whole signal) cannot enter the first fit: it would swamp it, and a value
  // near the largest double would overflow its sums. The iteration below judges these samples again.
  work.clear();
  for (const Pending& s : pending_) work.push_back(s.value);
  const double raw_median = median(work);
  for (double& w : work) w = std::abs(w - raw_median);
  const double raw_scale = std::max(kMadToSigma * median(work), floor);
  for (std::size_t i = 0; i < n; ++i)
    if (std::abs(pending_[i].value - raw_median) > 1e3 * raw_scale) out[i] = 1;

  Eigen::VectorXd x = Eigen::VectorXd::Zero(p);
  std::vector<double> residual(n);
  double scale = 0.0;
  for (int iteration = 0; iteration < 20; ++iteration) {
    Eigen::MatrixXd normal = ref_normal_;
    Eigen::VectorXd rhs = ref_rhs_;
    for (std::size_t i = 0; i < n; ++i) {
      if (out[i]) continue;
      const double* b = basis_of(i);
      for (int j = 0; j < p; ++j) {
        for (int k = j; k < p; ++k) normal(k, j) += b[k] * b[j];
        rhs[j] += b[j] * pending_[i].value;
      }
    }
    const Eigen::MatrixXd full = normal.selfadjointView<Eigen::Lower>();
    x = full.ldlt().solve(rhs);
    work.clear();
    for (std::size_t i = 0; i < n; ++i) {
      residual[i] = pending_[i].value - fit_at(i, x);
      if (!out[i]) work.push_back(residual[i]);
    }
    if (work.empty() || !x.allFinite()) break;
    const double center = median(work);
    work.clear();
    for (std::size_t i = 0; i < n; ++i)
      if (!out[i]) work.push_back(std::abs(residual[i] - center));
    scale = std::max(kMadToSigma * median(work), floor);
    // A short block (the dwell's last) estimates its spread from few samples: the previous block's holds too.
    if (n < static_cast<std::size_t>(options_.outlier_block_samples)) scale = std::max(scale, last_scale_);
    bool changed = false;
    for (std::size_t i = 0; i < n; ++i) {
      const char o = std::abs(residual[i] - center) > options_.outlier_threshold * scale ? 1 : 0;
      changed = changed || o != out[i];
      out[i] = o;
    }
    if (!changed) break;
  }
  if (!x.allFinite()) x.setZero();
  last_scale_ = scale;
  for (std::size_t i = 0; i < n; ++i) {
    const Pending& s = pending_[i];
    const double v = out[i] ? fit_at(i, x) : s.value;
    if (out[i]) ++outliers_;
    const double* b = basis_of(i);
    for (int j = 0; j < p; ++j) {
      for (int k = j; k < p; ++k) ref_normal_(k, j) += b[k] * b[j];
      ref_rhs_[j] += b[j] * v;
    }
    accumulate(s.t, s.gamma, &v, s.after_break);
  }
  pending_.clear();
}

void DwellAccumulator::flush() {
  if (finished_) return;
  finished_ = true;
  if (robust_) test_block();
  // The last revolution counts in the scatter as every other one does: every sample that moves the estimate
  // must be able to raise its uncertainty. It is complete when the dwell's last sample is within 1.5 sample
  // steps of a whole turn.
  if (with_std_err_ && !static_ && last_revolution_complete() && !revolution_broken_) close_revolution();
}

bool DwellAccumulator::last_revolution_complete() const {
  if (static_ || samples_ < 2) return false;
  const double span = std::abs(gamma_last_ - gamma_first_);
  const double step = span / static_cast<double>(samples_ - 1);
  return span - seen_revolution_ * 2.0 * kPi >= 2.0 * kPi - 1.5 * step;
}

int DwellAccumulator::complete_revolutions() const {
  return seen_revolution_ + (last_revolution_complete() ? 1 : 0);
}

void DwellAccumulator::accumulate(double t, double gamma, const double* values, bool after_break) {
  // Time scaled to about [-0.5, 0.5] over the planned dwell, for a well-conditioned drift column.
  const double ts = (t - t_first_) / duration_s_ - 0.5;

  if (static_) {
    for (int c = 0; c < columns_; ++c) static_sum_[c] += values[c];
    if (!with_std_err_) return;
    const int batch = static_cast<int>(std::floor((t - t_first_) / (duration_s_ / options_.static_batches)));
    if (batch != batch_index_ && batch_n_ > 0) {
      batches_.add(0.0, Eigen::VectorXd::Constant(1, batch_sum_ / static_cast<double>(batch_n_)));
      batch_sum_ = 0.0;
      batch_n_ = 0;
    }
    batch_index_ = batch;
    batch_sum_ += values[0];
    ++batch_n_;
    return;
  }

  // Revolutions counted from the first sample's gamma, in either sense of rotation.
  const int rev = static_cast<int>(std::floor(std::abs(gamma - gamma_first_) / (2.0 * kPi)));
  if (with_std_err_ && rev != revolution_) {
    if (revolution_broken_) {
      rev_normal_.setZero();
      rev_rhs_.setZero();
      rev_samples_ = 0;
      rev_time_sum_ = 0.0;
      if (rev_window_n_.size() > 0)
        rev_window_sum_.setZero(), rev_window_n_.setZero(), rev_window_t_.setZero();
      revolution_broken_ = false;
    } else {
      close_revolution();
    }
  }
  revolution_ = rev;
  // A gap inside this revolution: it is incomplete, so it counts in the dwell's fit but not in the scatter.
  if (after_break) revolution_broken_ = true;

  if (options_.method == ReduceOptions::Method::kHarmonicFit) {
    // The hot loop of a calibration: raw column-major storage, lower triangles only.
    double b[32];
    basis(gamma, ts, b);
    const int n = basis_size();
    double* __restrict normal = normal_.data();
    for (int j = 0; j < n; ++j) {
      const double bj = b[j];
      for (int i = j; i < n; ++i) normal[i + j * n] += b[i] * bj;
    }
    double* __restrict rhs = rhs_.data();
    for (int c = 0; c < columns_; ++c) {
      const double v = values[c];
      for (int i = 0; i < n; ++i) rhs[i + c * n] += b[i] * v;
    }
    if (with_std_err_) {
      const int nr = 2 * options_.harmonic_order + 1;
      double* __restrict rev_n = rev_normal_.data();
      for (int j = 0; j < nr; ++j) {
        const double bj = b[j];
        for (int i = j; i < nr; ++i) rev_n[i + j * nr] += b[i] * bj;
      }
      double* __restrict rev_rhs = rev_rhs_.data();
      for (int i = 0; i < nr; ++i) rev_rhs[i] += b[i] * values[0];
      ++rev_samples_;
      rev_time_sum_ += ts;
    }
    return;
  }

  // Window mean.
  const double half = 0.5 * options_.window_deg * kDegToRad;
  for (std::size_t k = 0; k < gammas_.size(); ++k) {
    if (std::abs(wrap_rad(gamma - gammas_[k])) > half) continue;
    const auto kk = static_cast<Eigen::Index>(k);
    for (int c = 0; c < columns_; ++c) {
      window_sum_(kk, c) += values[c];
      window_tsum_(kk, c) += ts * values[c];
    }
    window_n_[kk] += 1;
    window_t_[kk] += ts;
    window_tt_[kk] += ts * ts;
    if (with_std_err_) {
      rev_window_sum_[kk] += values[0];
      rev_window_n_[kk] += 1;
      rev_window_t_[kk] += ts;
    }
  }
}

void DwellAccumulator::close_revolution() {
  if (options_.method == ReduceOptions::Method::kHarmonicFit) {
    const int nr = 2 * options_.harmonic_order + 1;
    if (rev_samples_ >= static_cast<std::size_t>(2 * nr)) {
      const Eigen::MatrixXd full = rev_normal_.selfadjointView<Eigen::Lower>();
      const Eigen::VectorXd x = full.ldlt().solve(rev_rhs_);
      const double t_mean = rev_time_sum_ / static_cast<double>(rev_samples_);
      Eigen::VectorXd values(static_cast<Eigen::Index>(gammas_.size()));
      for (std::size_t k = 0; k < gammas_.size(); ++k) {
        double b[32];
        basis(gammas_[k], 0.0, b);
        double v = 0.0;
        for (int i = 0; i < nr; ++i) v += b[i] * x[i];
        values[static_cast<Eigen::Index>(k)] = v;
      }
      trend_.add(t_mean, values);
    }
    rev_normal_.setZero();
    rev_rhs_.setZero();
    rev_samples_ = 0;
    rev_time_sum_ = 0.0;
  } else {
    // A revolution counts when it passed through every window.
    if ((rev_window_n_.array() > 0).all()) {
      const double t_mean = rev_window_t_.sum() / rev_window_n_.sum();
      trend_.add(t_mean, rev_window_sum_.cwiseQuotient(rev_window_n_));
    }
    rev_window_sum_.setZero();
    rev_window_n_.setZero();
    rev_window_t_.setZero();
  }
}

void DwellAccumulator::RevolutionSums::add(double ti, const Eigen::VectorXd& vi) {
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

Eigen::MatrixXd DwellAccumulator::RevolutionSums::covariance_at(double t_mid, bool drift) const {
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

DwellValues DwellAccumulator::finish(int column) {
  flush();
  DwellValues out;
  const std::size_t ng = gammas_.size();
  out.value.assign(ng, kNaN);
  out.std_err.assign(ng, kNaN);
  out.samples.assign(ng, 0);
  if (samples_ == 0) return out;
  const double t_mid = (0.5 * (t_first_ + t_last_) - t_first_) / duration_s_ - 0.5;

  // Standard errors and covariance of the values at t_mid. The covariance's shape is the reduction
  // operator's (exact for white noise: one fit correlates the gammas of a dwell); its level is the scatter
  // between revolutions (or batches), pooled over the dwell's gammas: a 4 x 4 covariance estimated from a few
  // revolutions would weight a generalised least-squares fit worse than none.
  const auto set_covariance = [&](const RevolutionSums& sums, bool drift) {
    const Eigen::MatrixXd measured = sums.covariance_at(t_mid, drift);
    out.revolutions = static_cast<int>(sums.n);
    out.dof = 0.0;
    if (measured.size() == 0 || !measured.allFinite()) return;
    const Eigen::MatrixXd shape = white_noise_covariance();
    // Degrees of freedom: the revolutions' scatter about a line (or their mean), pooled over the gammas,
    // whose values are correlated as the shape says: a mean of ng scaled chi-squares with correlations
    // rho has ng^2 / sum(rho^2) times their degrees of freedom (docs/calibration.md).
    const Eigen::VectorXd sd = shape.diagonal().cwiseSqrt();
    const double rho2 = (shape.array() / (sd * sd.transpose()).array()).square().sum();
    out.dof = (sums.n - sums.parameters(drift)) * static_cast<double>(ng * ng) / rho2;
    const double level = (measured.diagonal().array() / shape.diagonal().array()).mean();
    out.covariance = level * shape;
    out.level = level;
    for (std::size_t k = 0; k < ng; ++k) {
      const auto kk = static_cast<Eigen::Index>(k);
      out.std_err[k] = std::sqrt(out.covariance(kk, kk));
    }
  };

  if (static_) {
    out.value[0] = static_sum_[column] / static_cast<double>(samples_);
    out.samples[0] = samples_;
    out.outliers = outliers_;
    if (with_std_err_ && column == 0) {
      RevolutionSums b = batches_;
      if (batch_n_ > 0) b.add(0.0, Eigen::VectorXd::Constant(1, batch_sum_ / static_cast<double>(batch_n_)));
      set_covariance(b, false);
    }
    return out;
  }

  if (options_.method == ReduceOptions::Method::kHarmonicFit) {
    const Eigen::MatrixXd full = normal_.selfadjointView<Eigen::Lower>();
    const Eigen::VectorXd x = full.ldlt().solve(rhs_.col(column));
    const int n = basis_size();
    for (std::size_t k = 0; k < ng; ++k) {
      double b[32];
      basis(gammas_[k], t_mid, b);
      double v = 0.0;
      for (int i = 0; i < n; ++i) v += b[i] * x[i];
      out.value[k] = v;
      out.samples[k] = samples_;
    }
  } else {
    for (std::size_t k = 0; k < ng; ++k) {
      const auto kk = static_cast<Eigen::Index>(k);
      const double nk = window_n_[kk];
      if (nk == 0) continue;
      const double mean = window_sum_(kk, column) / nk;
      double v = mean;
      if (options_.linear_drift) {
        const double tbar = window_t_[kk] / nk;
        const double stt = window_tt_[kk] - nk * tbar * tbar;
        const double stv = window_tsum_(kk, column) - nk * tbar * mean;
        if (stt > 0) v = mean + stv / stt * (t_mid - tbar);
      }
      out.value[k] = v;
      out.samples[k] = static_cast<std::size_t>(nk);
    }
  }
  if (with_std_err_ && column == 0) set_covariance(trend_, options_.linear_drift);
  out.outliers = outliers_;
  return out;
}

std::vector<double> DwellAccumulator::white_noise_gain() const {
  std::vector<double> gain(gammas_.size(), kNaN);
  if (samples_ == 0) return gain;
  const double t_mid = (0.5 * (t_first_ + t_last_) - t_first_) / duration_s_ - 0.5;
  if (static_) {
    gain[0] = 1.0 / static_cast<double>(samples_);
  } else if (options_.method == ReduceOptions::Method::kHarmonicFit) {
    const Eigen::MatrixXd full = normal_.selfadjointView<Eigen::Lower>();
    const auto ldlt = full.ldlt();
    const int n = basis_size();
    for (std::size_t k = 0; k < gammas_.size(); ++k) {
      Eigen::VectorXd b(n);
      basis(gammas_[k], t_mid, b.data());
      gain[k] = b.dot(ldlt.solve(b));
    }
  } else {
    for (std::size_t k = 0; k < gammas_.size(); ++k) {
      const auto kk = static_cast<Eigen::Index>(k);
      const double nk = window_n_[kk];
      if (nk == 0) continue;
      double g = 1.0 / nk;
      if (options_.linear_drift) {
        const double tbar = window_t_[kk] / nk, stt = window_tt_[kk] - nk * tbar * tbar;
        if (stt > 0) g += (t_mid - tbar) * (t_mid - tbar) / stt;
      }
      gain[k] = g;
    }
  }
  return gain;
}

Eigen::MatrixXd DwellAccumulator::white_noise_covariance() const {
  const auto ng = static_cast<Eigen::Index>(gammas_.size());
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(ng, ng);
  if (samples_ > 0 && !static_ && options_.method == ReduceOptions::Method::kHarmonicFit) {
    const double t_mid = (0.5 * (t_first_ + t_last_) - t_first_) / duration_s_ - 0.5;
    const Eigen::MatrixXd full = normal_.selfadjointView<Eigen::Lower>();
    Eigen::MatrixXd b(basis_size(), ng);
    for (Eigen::Index k = 0; k < ng; ++k) basis(gammas_[static_cast<std::size_t>(k)], t_mid, b.col(k).data());
    cov = b.transpose() * full.ldlt().solve(b);
  } else {
    const std::vector<double> gain = white_noise_gain();
    for (Eigen::Index k = 0; k < ng; ++k) cov(k, k) = gain[static_cast<std::size_t>(k)];
  }
  return cov;
}

}  // namespace gyrocal
