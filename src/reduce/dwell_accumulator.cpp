#include "gyrocal/reduce/dwell_accumulator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include <Eigen/Cholesky>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"

namespace gyrocal {
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
