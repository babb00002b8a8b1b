#include "gyrocal/reduce/dwell_accumulator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include <Eigen/Cholesky>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "robust_statistics.hpp"

namespace gyrocal {

using reduce_detail::kMadToSigma;
using reduce_detail::median;
using reduce_detail::none_beyond;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

DwellAccumulator::DwellAccumulator(const ReduceOptions& options, std::vector<double> gammas_rad,
                                   bool is_static, int columns, double planned_duration_s, bool with_std_err,
                                   double sweep_rate_rad_s)
    : options_(options),
      spinning_(!is_static),
      gammas_(gammas_rad.size()),
      duration_s_(planned_duration_s),
      with_std_err_(with_std_err),
      reduction_(make_dwell_reduction(options, std::move(gammas_rad), is_static, columns, with_std_err)) {
  // docs/physics.md section 15: the heading's sweep, spinning only (held, the platform does not turn).
  if (spinning_ && sweep_rate_rad_s != 0.0) sweep_scaled_ = sweep_rate_rad_s * duration_s_;
  scatter_.sweep = sweep_scaled_;
  robust_ = with_std_err_ && columns == 1 && options_.outlier_threshold > 0.0;
  if (robust_) {
    const int nd = detection_size();
    ref_normal_ = Eigen::MatrixXd::Zero(nd, nd);
    ref_rhs_ = Eigen::VectorXd::Zero(nd);
  }
}

int DwellAccumulator::detection_size() const {
  return spinning_ ? 2 * options_.harmonic_order + 2 + (sweep_scaled_ != 0.0 ? 2 : 0) : 2;
}

// The outlier rule's fit: harmonics and a linear drift (a static hold: mean and drift), whatever the
// reduction; and the heading's sweep at a counter rate offset (docs/physics.md section 15).
void DwellAccumulator::detection_basis(double cos_gamma, double sin_gamma, double t_scaled,
                                       double* out) const {
  if (!spinning_) {
    out[0] = 1.0;
    out[1] = t_scaled;
    return;
  }
  harmonic_basis(cos_gamma, sin_gamma, options_.harmonic_order, out);
  out[2 * options_.harmonic_order + 1] = t_scaled;
  if (sweep_scaled_ != 0.0) {
    out[2 * options_.harmonic_order + 2] = std::cos(sweep_scaled_ * (t_scaled + 0.5));
    out[2 * options_.harmonic_order + 3] = std::sin(sweep_scaled_ * (t_scaled + 0.5));
  }
}

int DwellAccumulator::period_of(double t, double gamma_rad) const {
  if (spinning_) return revolution_of(gamma_rad);
  return static_cast<int>(std::floor((t - t_first_) / (duration_s_ / options_.static_batches)));
}

double DwellAccumulator::scaled_mid_time() const {
  return scaled_time(0.5 * (t_first_ + t_last_));
}

void DwellAccumulator::add_general(double t, double gamma, const double* values) {
  if (samples_ == 0) {
    t_first_ = t;
    gamma_first_ = gamma;
  }
  t_last_ = t;
  gamma_last_ = gamma;
  ++samples_;
  // Its period, found once (revolution_of was 4 % of a calibration's time, computed twice a sample).
  const int period = spinning_ ? revolution_of(gamma) : with_std_err_ ? period_of(t, gamma) : 0;
  if (spinning_) seen_revolution_ = period;
  const bool after_break = break_next_;
  break_next_ = false;
  if (!robust_) {
    accumulate(t, gamma, period, values, after_break);
    return;
  }
  // A block closes where a revolution begins (a static hold: anywhere) once it holds enough samples.
  const std::size_t block = static_cast<std::size_t>(options_.outlier_block_samples);
  const bool boundary = !spinning_ || seen_revolution_ != block_revolution_;
  if ((boundary && pending_.size() >= block) || pending_.size() >= kMaxBlockSamples) test_block();
  block_revolution_ = seen_revolution_;
  pending_.push_back({t, gamma, values[0], period, after_break, samples_ - 1});
}

void DwellAccumulator::add_sums(double first_time_s, double last_time_s, std::size_t samples,
                                const Eigen::MatrixXd& normal, const Eigen::MatrixXd& rhs) {
  if (samples_ != 0 || with_std_err_ || samples == 0)
    throw Error("DwellAccumulator::add_sums: only once, on an empty accumulator without standard errors");
  t_first_ = first_time_s;
  t_last_ = last_time_s;
  samples_ = samples;
  if (auto* fit = std::get_if<HarmonicFit>(&reduction_))
    fit->add_sums(samples, normal, rhs);
  else if (auto* mean = std::get_if<StaticMean>(&reduction_))
    mean->add_sums(samples, rhs);
  else
    throw Error("DwellAccumulator::add_sums: a window mean takes its samples one by one");
}

void DwellAccumulator::break_revolution() {
  if (samples_ > 0) break_next_ = true;
}

// docs/physics.md section 14: each sample's residual about the fit of the dwell so far and its block; beyond
// outlier_threshold robust standard deviations of the block's residuals it is an outlier, the fit is
// repeated without the outliers and the test with it, until the outliers do not change. Outliers are left
// out of the fit, and their numbers kept, so that the model terms go through the same operator
// (docs/calibration.md, "Spikes").
void DwellAccumulator::test_block() {
  const std::size_t n = pending_.size();
  if (n == 0) return;
  const int p = detection_size();
  const auto pp = static_cast<std::size_t>(p);
  scratch_basis_.resize(n * pp);
  // A spinning dwell's cos gamma and sin gamma by rotation from the previous sample's (gamma advances by a
  // few hundredths of a radian a sample; the difference of two close doubles is exact): a libm sincos a
  // sample was 4 % of a calibration's time. A true sincos every kResync samples, after a step beyond
  // kMaxStep and at the block's first sample bounds the rotations' rounding to ~kResync ulps (1e-14).
  constexpr std::size_t kResync = 64;
  constexpr double kMaxStep = 0.05;  // rad: the series below are then exact to 1e-17
  // Where the harmonic fit's basis is the detection basis (harmonics and drift, no sweep: the default), the
  // sums of b b' and b v both fits need are formed once, per run of samples in one period (the fit's
  // revolution sums need them apart), instead of per sample for each fit, and the sums of b b' from the
  // harmonics' moments (HarmonicMoments, about half the operations of the products); the fit then takes
  // each run's sums whole (HarmonicFit::add_run) when the block has no outlier.
  auto* const fit = std::get_if<HarmonicFit>(&reduction_);
  const bool shared = fit != nullptr && spinning_ && fit->basis_size() == p && fit->fits_drift();
  std::vector<BlockRun>& runs = scratch_runs_;
  runs.clear();
  scratch_run_normal_.clear();
  scratch_run_rhs_.clear();
  HarmonicMoments moments(options_.harmonic_order);
  const auto close_run = [&] {
    if (!runs.empty()) moments.lower(&scratch_run_normal_[(runs.size() - 1) * pp * pp]);
  };
  double* rhs_sum = nullptr;
  double cos_g = 0.0, sin_g = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Pending& sample = pending_[i];
    const double gamma = sample.gamma;
    const double step = i > 0 ? gamma - pending_[i - 1].gamma : 0.0;
    if (!spinning_) {
      cos_g = 1.0, sin_g = 0.0;  // a static hold's basis is the mean and the drift
    } else if (i % kResync == 0 || !(std::abs(step) <= kMaxStep)) {
      cos_g = std::cos(gamma);
      sin_g = std::sin(gamma);
    } else {
      const double d2 = step * step;
      const double sd = step * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0)));
      const double cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0 * (1.0 - d2 / 56.0)));
      const double cn = cos_g * cd - sin_g * sd;
      sin_g = sin_g * cd + cos_g * sd;
      cos_g = cn;
    }
    double* const b = &scratch_basis_[i * pp];
    if (!shared) {
      detection_basis(cos_g, sin_g, scaled_time(sample.t), b);
      continue;
    }
    if (i == 0 || sample.period != pending_[i - 1].period) {
      close_run();
      runs.push_back({0, sample.period, false, 0.0});
      scratch_run_normal_.resize(runs.size() * pp * pp, 0.0);
      scratch_run_rhs_.resize(runs.size() * pp, 0.0);
      rhs_sum = &scratch_run_rhs_[(runs.size() - 1) * pp];
      moments = HarmonicMoments(options_.harmonic_order);
    }
    const double t_scaled = scaled_time(sample.t);
    moments.add(cos_g, sin_g, t_scaled, b);
    if (p == 8) {  // the default order 3, unrolled
      for (int k = 0; k < 8; ++k) rhs_sum[k] += b[k] * sample.value;
    } else {
      for (int k = 0; k < p; ++k) rhs_sum[k] += b[k] * sample.value;
    }
    BlockRun& run = runs.back();
    ++run.count;
    run.t_scaled_sum += t_scaled;
    run.after_break = run.after_break || sample.after_break;
  }
  close_run();
  const auto basis_of = [&](std::size_t i) { return &scratch_basis_[i * pp]; };
  Eigen::MatrixXd block_normal;
  Eigen::VectorXd block_rhs;
  if (shared) {
    block_normal = Eigen::MatrixXd::Zero(p, p);
    block_rhs = Eigen::VectorXd::Zero(p);
    for (std::size_t k = 0; k < runs.size(); ++k) {
      block_normal += Eigen::Map<const Eigen::MatrixXd>(&scratch_run_normal_[k * pp * pp], p, p);
      block_rhs += Eigen::Map<const Eigen::VectorXd>(&scratch_run_rhs_[k * pp], p);
    }
  }
  const auto fit_at = [&](std::size_t i, const Eigen::VectorXd& x) {
    const double* b = basis_of(i);
    double v = 0.0;
    if (p == 8) {  // the default order 3, unrolled
      for (int k = 0; k < 8; ++k) v += b[k] * x[k];
    } else {
      for (int k = 0; k < p; ++k) v += b[k] * x[k];
    }
    return v;
  };

  std::vector<char> out(n, 0);
  std::vector<double> work;
  work.reserve(n);
  // Residuals below a part in 1e9 of the output are rounding, never outliers (a noise-free record): the floor
  // 1e-9 (1 + median |value|), computed when a bound does not settle the question (at least floor_lo).
  std::vector<double> abs_values;
  abs_values.reserve(n);
  for (const Pending& s : pending_) abs_values.push_back(std::abs(s.value));
  const double floor_lo = 1e-9 * (1.0 + *std::min_element(abs_values.begin(), abs_values.end()));
  double floor_value = -1.0;
  const auto floor_of = [&] {
    if (floor_value < 0.0) floor_value = 1e-9 * (1.0 + median(abs_values));
    return floor_value;
  };
  // A first screen on the raw values: a sample a thousand times further from the block's median than their
  // robust spread (which holds the whole signal) cannot enter the first fit: it would swamp it, and a value
  // near the largest double would overflow its sums. The iteration below judges these samples again.
  work.clear();
  for (const Pending& s : pending_) work.push_back(s.value);
  const bool screened = !none_beyond(work, 1e3, floor_lo);
  if (screened) {
    const double floor = floor_of();
    const double raw_median = median(work);
    for (double& w : work) w = std::abs(w - raw_median);
    const double raw_scale = std::max(kMadToSigma * median(work), floor);
    for (std::size_t i = 0; i < n; ++i)
      if (std::abs(pending_[i].value - raw_median) > 1e3 * raw_scale) out[i] = 1;
  }

  Eigen::VectorXd x = Eigen::VectorXd::Zero(p);
  std::vector<double> residual(n);
  double scale = 0.0;
  // The last iteration's normal equations, when they were formed with the final set of outliers: the
  // dwell's sums then need only the outliers' terms added (below), not every sample's again.
  Eigen::MatrixXd normal;
  Eigen::VectorXd rhs;
  bool settled = false, scale_pending = false;
  const Eigen::MatrixXd ref_normal_before = ref_normal_;
  for (int iteration = 0; iteration < 20; ++iteration) {
    normal = ref_normal_;
    rhs = ref_rhs_;
    const bool any_out = std::find(out.begin(), out.end(), 1) != out.end();
    if (shared && !any_out) {
      normal += block_normal;
      rhs += block_rhs;
    } else {
      for (std::size_t i = 0; i < n; ++i) {
        if (out[i]) continue;
        const double* b = basis_of(i);
        add_outer_product(normal.data(), b, p);
        for (int j = 0; j < p; ++j) rhs[j] += b[j] * pending_[i].value;
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
    const bool short_block = n < static_cast<std::size_t>(options_.outlier_block_samples);
    // No sample screened out and none can be an outlier, whatever the exact median and scale (the common
    // case): settled on this fit, the block's scale computed only if a short block asks for it.
    if (iteration == 0 && !screened && !short_block &&
        none_beyond(work, options_.outlier_threshold, floor_lo)) {
      settled = true;
      scale_pending = true;
      break;
    }
    const double center = median(work);
    work.clear();
    for (std::size_t i = 0; i < n; ++i)
      if (!out[i]) work.push_back(std::abs(residual[i] - center));
    scale = std::max(kMadToSigma * median(work), floor_of());
    // A short block (the dwell's last) estimates its spread from few samples: the previous block's holds too.
    if (short_block) scale = std::max(scale, last_scale());
    bool changed = false;
    for (std::size_t i = 0; i < n; ++i) {
      const char o = std::abs(residual[i] - center) > options_.outlier_threshold * scale ? 1 : 0;
      changed = changed || o != out[i];
      out[i] = o;
    }
    if (!changed) {
      settled = true;
      break;
    }
  }
  if (!x.allFinite()) {
    x.setZero();
    settled = false;
  }
  last_scale_ = scale;
  last_scale_pending_ = scale_pending;
  if (scale_pending) {
    last_residuals_.swap(work);  // the residuals of every sample, none out
    last_abs_values_.swap(abs_values);
  }
  if (settled) {
    ref_normal_ = std::move(normal);
    ref_rhs_ = std::move(rhs);
  }
  // An outlier is left out of the fit (as the settled normal equations already leave it): replaced by the
  // fit's value it would be the same for a signal the fit holds whole, but a drive's ripple moves an
  // accelerometer's output by far more than the fit holds (docs/accelerometer.md), and the model terms
  // that follow the measured motion leave out the same samples (outlier_samples), so the two stay one
  // operator. Without outliers the block's runs serve the reference sums and the fit whole; a block with
  // outliers adds its kept samples one by one, and a gap's mark passes to the next sample kept.
  const bool use_shared = shared && std::find(out.begin(), out.end(), 1) == out.end();
  if (use_shared) {
    ref_normal_ = ref_normal_before + block_normal;
    if (!settled) ref_rhs_ += block_rhs;
    for (std::size_t k = 0; k < runs.size(); ++k) {
      enter_period(runs[k].period, runs[k].after_break);
      fit->add_run(runs[k].count, runs[k].t_scaled_sum, &scratch_run_normal_[k * pp * pp],
                   &scratch_run_rhs_[k * pp]);
    }
    pending_.clear();
    return;
  }
  bool carry_break = false;
  for (std::size_t i = 0; i < n; ++i) {
    const Pending& s = pending_[i];
    if (out[i]) {
      ++outliers_;
      outlier_samples_.push_back(s.index);
      carry_break = carry_break || s.after_break;
      continue;
    }
    if (!settled) {
      const double* b = basis_of(i);
      add_outer_product(ref_normal_.data(), b, p);
      for (int j = 0; j < p; ++j) ref_rhs_[j] += b[j] * s.value;
    }
    accumulate(s.t, s.gamma, s.period, &s.value, s.after_break || carry_break, basis_of(i));
    carry_break = false;
  }
  pending_.clear();
}

// The scale of the block tested last: kept, or computed now from what test_block kept (as it would have).
double DwellAccumulator::last_scale() {
  if (last_scale_pending_) {
    last_scale_pending_ = false;
    const double center = median(last_residuals_);
    for (double& r : last_residuals_) r = std::abs(r - center);
    const double floor = 1e-9 * (1.0 + median(last_abs_values_));
    last_scale_ = std::max(kMadToSigma * median(last_residuals_), floor);
  }
  return last_scale_;
}

void DwellAccumulator::flush() {
  if (finished_) return;
  finished_ = true;
  if (robust_) test_block();
  // The last period counts in the scatter as every other one does: every sample that moves the estimate
  // must be able to raise its uncertainty. A static hold's last batch always; a revolution when it is
  // complete: the dwell's last sample within 1.5 sample steps of a whole turn, without a gap.
  if (!with_std_err_) return;
  if (spinning_ && (!last_revolution_complete() || period_broken_)) return;
  scatter_.index = period_;
  std::visit([&](auto& method) { method.close_period(scatter_); }, reduction_);
}

bool DwellAccumulator::last_revolution_complete() const {
  if (!spinning_ || samples_ < 2) return false;
  const double span = std::abs(gamma_last_ - gamma_first_);
  const double step = span / static_cast<double>(samples_ - 1);
  return span - seen_revolution_ * 2.0 * kPi >= 2.0 * kPi - 1.5 * step;
}

int DwellAccumulator::complete_revolutions() const {
  return seen_revolution_ + (last_revolution_complete() ? 1 : 0);
}

void DwellAccumulator::enter_period(int period, bool after_break) {
  if (!with_std_err_) return;
  if (period != period_) {
    scatter_.index = period_;
    std::visit(
        [&](auto& method) {
          if (period_broken_)
            method.discard_period();
          else
            method.close_period(scatter_);
        },
        reduction_);
    period_broken_ = false;
  }
  period_ = period;
  // A gap inside this revolution: it is incomplete, so it counts in the dwell's fit but not in the scatter.
  if (after_break && spinning_) period_broken_ = true;
}

void DwellAccumulator::accumulate(double t, double gamma, int period, const double* values, bool after_break,
                                  const double* basis) {
  enter_period(period, after_break);
  const double ts = scaled_time(t);
  // The outlier rule's basis begins with the harmonic fit's (harmonic_basis at gamma, then the scaled time):
  // evaluated once, not twice.
  if (basis != nullptr) {
    if (auto* fit = std::get_if<HarmonicFit>(&reduction_)) return fit->add_basis(ts, basis, values);
  }
  std::visit([&](auto& method) { method.add(ts, gamma, values); }, reduction_);
}

DwellValues DwellAccumulator::finish(int column) {
  flush();
  DwellValues out;
  out.value.assign(gammas_, kNaN);
  out.std_err.assign(gammas_, kNaN);
  out.samples.assign(gammas_, 0);
  if (samples_ == 0) return out;
  const double t_mid = scaled_mid_time();
  std::visit([&](const auto& method) { method.values(column, t_mid, out); }, reduction_);
  out.outliers = outliers_;
  if (column == 0) out.outlier_samples = outlier_samples_;
  if (!with_std_err_ || column != 0) return out;

  // Standard errors and covariance of the values at t_mid. The covariance's shape is the reduction
  // operator's (exact for white noise: one fit correlates the gammas of a dwell); its level is the scatter
  // between revolutions (or batches), pooled over the dwell's gammas: a 4 x 4 covariance estimated from a few
  // revolutions would weight a generalised least-squares fit worse than none.
  const bool drift = std::visit([](const auto& method) { return method.fits_drift(); }, reduction_);
  out.periods = scatter_.periods;
  out.scatter_t_mid = t_mid;
  out.scatter_sweep = scatter_.sweep;
  out.scatter_drift = drift;
  out.shape = white_noise_covariance();
  state_level(out, scatter_);
  return out;
}

void DwellAccumulator::state_level(DwellValues& out, const RevolutionSums& scatter) {
  const double t_mid = out.scatter_t_mid;
  const bool drift = out.scatter_drift;
  const std::size_t gammas = out.value.size();
  const Eigen::MatrixXd measured = scatter.covariance_at(t_mid, drift);
  out.revolutions = static_cast<int>(scatter.n);
  out.dof = 0.0;
  if (measured.size() == 0 || !measured.allFinite()) return;
  const Eigen::MatrixXd& shape = out.shape;
  // Degrees of freedom: the revolutions' scatter about a line (or their mean), pooled over the gammas,
  // whose values are correlated as the shape says: a mean of ng scaled chi-squares with correlations
  // rho has ng^2 / sum(rho^2) times their degrees of freedom (docs/calibration.md).
  const Eigen::VectorXd sd = shape.diagonal().cwiseSqrt();
  const double rho2 = (shape.array() / (sd * sd.transpose()).array()).square().sum();
  out.dof = (scatter.n - scatter.parameters(drift)) * static_cast<double>(gammas * gammas) / rho2;
  const double level = (measured.diagonal().array() / shape.diagonal().array()).mean();
  out.covariance = level * shape;
  out.level = level;
  for (std::size_t k = 0; k < gammas; ++k) {
    const auto kk = static_cast<Eigen::Index>(k);
    out.std_err[k] = std::sqrt(out.covariance(kk, kk));
  }
}

void relevel_from_periods(DwellValues& v, const std::vector<PeriodValues>& periods) {
  if (v.shape.size() == 0) return;
  RevolutionSums scatter;
  scatter.sweep = v.scatter_sweep;
  for (const PeriodValues& p : periods) {
    scatter.index = p.index;
    scatter.add(p.t_scaled, p.values);
  }
  v.covariance.resize(0, 0);
  v.level = std::numeric_limits<double>::quiet_NaN();
  v.std_err.assign(v.value.size(), std::numeric_limits<double>::quiet_NaN());
  DwellAccumulator::state_level(v, scatter);
}

std::vector<double> DwellAccumulator::white_noise_gain() const {
  if (samples_ == 0) return std::vector<double>(gammas_, kNaN);
  const double t_mid = scaled_mid_time();
  return std::visit([&](const auto& method) { return method.white_noise_gain(t_mid); }, reduction_);
}

Eigen::MatrixXd DwellAccumulator::white_noise_covariance() const {
  const auto ng = static_cast<Eigen::Index>(gammas_);
  if (samples_ == 0) {
    Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(ng, ng);
    cov.diagonal().setConstant(kNaN);
    return cov;
  }
  const double t_mid = scaled_mid_time();
  return std::visit([&](const auto& method) { return method.white_noise_covariance(t_mid); }, reduction_);
}

}  // namespace gyrocal
