#pragma once
// The reduction of one dwell: a linear operator from a dwell's samples to one value per gamma of the
// plan. The same operator reduces the gyro output and, in the identify stage, the model terms
// (omega_I and the drift regressors) evaluated on the dwell's samples, so that
//   reduce(W) = reduce(omega_I) + sum_j c_j reduce(x_j)
// holds exactly whatever harmonics the machine's errors add.
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gyrocal/reduce/dwell_reduction.hpp"

namespace gyrocal {

/// How a dwell is reduced. Defaults as stated; IsValid() checks them.
struct ReduceOptions {
  enum class Method {
    kHarmonicFit,  ///< least-squares fit of a harmonic series in gamma plus a linear drift in time (default)
    kWindowMean,   ///< mean of the samples within +-window/2 of each gamma
  };
  Method method = Method::kHarmonicFit;
  int harmonic_order = 3;    ///< harmonic fit: orders 0..harmonic_order in gamma
  bool linear_drift = true;  ///< harmonic fit and window mean: a linear drift in time
  double window_deg = 10.0;  ///< window mean: full width of the window around each gamma, deg

  // Finding dwells in a record as a rig writes it (docs/physics.md section 14; docs/calibration.md, "Cutting
  // a record into dwells"). Steadiness is judged on straight lines fitted to windows of encoder readings,
  // never from one sample to the next, so jitter, quantisation and a toggling count do not break a dwell.
  /// Length of the windows on which a steady state is recognised and its rate re-checked, s. Physics section
  /// 14 asks for >= 0.25 s; 0.5 s measures a 10 rad/s rate to ~4e-5 through 0.1 deg quantisation at 200 Hz.
  double window_s = 0.5;
  /// A reading further than this from the line of the dwell's last window leaves the steady state, deg:
  /// ten times what 0.1 deg quantisation (+-0.05), 0.1 ms stamp jitter at 10 rad/s (+-0.06) and 2e-4 rate
  /// ripple (0.01) can explain together; a ramp away from 10 rad/s at 2 rad/s^2 crosses it within 0.1 s.
  double angle_tolerance_deg = 0.5;
  /// Beta (and a static hold's gamma) matches the plan within this, and beta (and a static hold's main and
  /// counter angles) stays within it of the dwell's value, deg: four 0.1 deg encoder quanta and a toggling
  /// count, far below any two planned positions' separation.
  double beta_tolerance_deg = 0.2;
  /// A steady rate matches a planned rate within this (relative), and the counter platform turns at minus
  /// the main rate within it: a drive may differ from its nominal rate by up to 1e-3 (the measured rate is
  /// used), twice that for margin.
  double rate_tolerance = 2e-3;
  /// Each window's rate stays within this (relative) of the dwell's rate: ripple up to 2e-4, five times.
  double rate_steadiness = 1e-3;
  double static_rate_tolerance_rad_s = 0.01;  ///< below this the main axis (or platform) counts as stopped
  /// A dwell's main encoder leaving its constant-rate line by more than this RMS, beyond its sample-to-sample
  /// scatter (quantisation, jitter), is warned about ("the rate wanders"), deg: the model terms follow the
  /// line.
  double wander_warning_deg = 0.01;
  /// An interval between two rows longer than this many planned sample intervals is a gap (a dwell with
  /// gaps is still one dwell; inside a dwell each gap counts as one sample interval, since a clock jump
  /// looks the same).
  double gap_intervals = 1.5;
  /// At most this many consecutive rows whose encoders leave the dwell's line (or beta its value) and come
  /// back are dropped as encoder glitches; more end the dwell.
  int encoder_glitch_rows = 3;
  /// The machine is seen leaving a dwell only once an encoder has left its tolerance: a platform starting a
  /// move at 20 deg/s^2 leaves beta_tolerance_deg after 0.14 s, and encoder_glitch_rows more rows pass
  /// before the run ends. The samples of this last interval before the end of a run that left its steady
  /// state are dropped (counted as "before_leaving"), since the model terms assume the steady state,
  /// s. A run that ends at its planned duration or with the record loses nothing.
  double leave_guard_s = 0.25;
  /// A dwell broken into more stretches than this (by gaps and glitches) is refused: the model terms keep one
  /// entry per stretch, so this bounds their memory.
  int max_stretches_per_dwell = 4096;
  int static_batches = 16;  ///< a static hold's standard error from this many batch means
  /// The model terms (identify/model_terms.hpp) are smooth in gamma (harmonics up to ~6), so they are
  /// evaluated on every k-th sample of a dwell with k chosen to keep at least this many samples per
  /// revolution (and 64 per static hold); the dwell's first and last samples are always in. 0 (default):
  /// every sample, the only choice that is exact on any configuration (docs/calibration.md: a stride of 32
  /// per revolution left 4.3e-6 deg/h/g^2 on dOS with large machine errors).
  int model_samples_per_revolution = 0;
  /// Spikes (docs/physics.md section 14): a sample of the gyro output whose residual about the dwell's fit
  /// lies more than this many robust standard deviations (1.4826 x the median absolute deviation of the
  /// residuals of its block) from the block's median residual is an outlier; iterated until the set of
  /// outliers is stable. It is counted and left out of the fit (docs/calibration.md, "Spikes"). 0: no
  /// rejection.
  double outlier_threshold = 6.0;
  /// The rule tests whole revolutions (a static hold: runs of samples) in blocks of at least this many
  /// samples, against the fit of the dwell so far and the block: the memory of one block.
  int outlier_block_samples = 128;

  /// True when every option is in range; otherwise false with a sentence in *error.
  bool IsValid(std::string* error) const;
};

/// The result of reducing one dwell for one column of values.
struct DwellValues {
  std::vector<double> value;  ///< per gamma, in the values' unit
  /// Per gamma: the square root of the covariance's diagonal; NaN if unknown.
  std::vector<double> std_err;
  /// Covariance (unit^2) of the values at the gammas of this dwell: they come from one fit, so they are
  /// correlated (-1/7 for a harmonic fit of order 3 under white noise). Its shape is the reduction
  /// operator's, its level the scatter between revolutions (or batches) pooled over the gammas. Empty when
  /// not computed.
  Eigen::MatrixXd covariance;
  std::vector<std::size_t> samples;  ///< per gamma: samples that entered
  int revolutions = 0;               ///< complete revolutions (or batches) the standard error comes from
  /// Degrees of freedom of the covariance's level: the scatter of `revolutions` values about a line (or
  /// their mean), pooled over the gammas (docs/calibration.md, "Degrees of freedom"). +inf when the
  /// covariance is known rather than measured (a prediction); 0 when there is no scatter to measure.
  double dof = std::numeric_limits<double>::infinity();
  /// The covariance's level: the white-noise variance per sample, unit^2, that the scatter implies
  /// (covariance = level x the operator's white-noise covariance). NaN when not measured.
  double level = std::numeric_limits<double>::quiet_NaN();
  /// Samples rejected as outliers (ReduceOptions::outlier_threshold) and left out of the fit.
  std::size_t outliers = 0;
  /// Their numbers in the dwell (from 0, in the order added), ascending: the model terms evaluated
  /// sample by sample where they follow the measured motion leave out the same samples
  /// (identify/model_terms.hpp).
  std::vector<std::size_t> outlier_samples;
  /// With the standard errors: the values of each period (revolution or batch) that entered the scatter,
  /// the fit in time the scatter is taken about (mid-time, drift, the sweep's phase rate), and the
  /// operator's white-noise covariance (the covariance's shape), so that the level can be measured again
  /// from the scatter of the periods' values minus a model's (relevel_from_periods).
  std::vector<PeriodValues> periods;
  double scatter_t_mid = 0.0, scatter_sweep = 0.0;
  bool scatter_drift = false;
  Eigen::MatrixXd shape;
};

/// `v`'s covariance level (and std_err, dof, revolutions) measured again, as DwellAccumulator::finish
/// measures it, from the scatter between `periods` (per period of v.periods, the same index and time, other
/// values: e.g. the output's minus the model's, identify/calibration.cpp) about v's fit in time, with v's
/// shape. Periods missing from `periods` do not count. v is left as it was when it holds no shape.
void relevel_from_periods(DwellValues& v, const std::vector<PeriodValues>& periods);

/// Accumulates one dwell's samples (streaming, memory independent of the dwell's length) and reduces them.
/// Spinning dwell: the values at each gamma of `gammas_rad`. Static hold: one value (the mean).
///
/// The method's own sums live in a DwellReduction (reduce/dwell_reduction.hpp: StaticMean, HarmonicFit or
/// WindowMean, picked by make_dwell_reduction); this class holds what every method shares: the samples' time
/// and angle span, the outlier rule with its pending block, the periods (revolutions of a spinning dwell,
/// batches of a static hold) and the scatter of their values, with the heading's sweep at a counter rate
/// offset.
class DwellAccumulator {
 public:
  /// columns: how many value columns each sample carries (1 for the gyro output, more for model terms).
  /// planned_duration_s: the planned length of the measured part (> 0), to scale time and size batches.
  /// with_std_err: also compute the standard errors of column 0 (scatter between revolutions or batches).
  /// sweep_rate_rad_s: a spinning dwell at a counter rate offset (docs/physics.md section 15) turns the
  /// platform's heading at this rate, and the Earth rate's horizontal part sweeps through the output as
  /// cos and sin of sweep_rate * (t - t_first): not a harmonic of gamma, and tens of thousands of times the
  /// noise. The outlier rule and the scatter between revolutions (the standard errors' level) fit these two
  /// terms too, so that they measure the noise, not the sweep. The values stay the plain fit's: fitted over
  /// the fraction of a sweep a dwell holds, the two terms would take the constant's place and multiply its
  /// variance; the same operator reduces the model terms, so the sweep is carried, not lost. 0
  /// (default): none.
  DwellAccumulator(const ReduceOptions& options, std::vector<double> gammas_rad, bool is_static, int columns,
                   double planned_duration_s, bool with_std_err, double sweep_rate_rad_s = 0.0);

  /// One sample at time t (s) and arm angle gamma (rad, unwrapped: it must progress monotonically while
  /// spinning), with `columns` values. With outlier rejection (with_std_err, one column and
  /// ReduceOptions::outlier_threshold > 0) samples wait in a block of whole revolutions (at least
  /// outlier_block_samples) until the block is tested; finish() tests the last one.
  void add(double time_s, double gamma_rad, const double* values) {
    // The usual sample of a record's spinning dwell, inline (a call a sample from the reducer was measurable
    // in calibrate's time); the first sample, one after a gap and every other case go out of line.
    if (robust_ && spinning_ && samples_ > 0 && !break_next_) {
      t_last_ = time_s;
      gamma_last_ = gamma_rad;
      ++samples_;
      const int period = revolution_of(gamma_rad);
      seen_revolution_ = period;
      const std::size_t block = static_cast<std::size_t>(options_.outlier_block_samples);
      if ((period != block_revolution_ && pending_.size() >= block) || pending_.size() >= kMaxBlockSamples)
        test_block();
      block_revolution_ = period;
      pending_.push_back({time_s, gamma_rad, values[0], period, false, samples_ - 1});
      return;
    }
    add_general(time_s, gamma_rad, values);
  }
  /// A whole dwell's samples at once, given by their sums (identify/model_terms.hpp: the model terms summed
  /// in closed form): `samples` samples from first_time_s to last_time_s (s); for a harmonic fit `normal` and
  /// `rhs` as HarmonicFit::add_sums takes them (the basis' time is scaled as add() scales it), for a static
  /// hold rhs's one row holds the columns' sums (`normal` unused). Only on an accumulator without standard
  /// errors that has no sample yet; a window mean cannot (it throws).
  void add_sums(double first_time_s, double last_time_s, std::size_t samples, const Eigen::MatrixXd& normal,
                const Eigen::MatrixXd& rhs);
  /// The time scaled as the reduction's basis takes it: (t - first) / planned_duration - 0.5, with `first`
  /// the dwell's first sample's time.
  static double scaled_time(double time_s, double first_time_s, double planned_duration_s) {
    return (time_s - first_time_s) / planned_duration_s - 0.5;
  }

  /// The reduced values of column `column`, evaluated at the dwell's mid-time. The first call ends the
  /// accumulation (it tests the block still waiting and closes the last revolution).
  DwellValues finish(int column);

  /// Per gamma: the variance of the reduced value per unit variance of white noise on each sample,
  /// i.e. sum_i a_i^2 for the operator value = sum_i a_i y_i (b' (Phi' Phi)^-1 b for the harmonic fit).
  std::vector<double> white_noise_gain() const;
  /// gamma x gamma: the covariance of the reduced values per unit variance of white noise on each sample,
  /// whose diagonal is white_noise_gain(). The harmonic fit's values at different gammas share its
  /// coefficients, so they are correlated; the window mean's are not.
  Eigen::MatrixXd white_noise_covariance() const;

  std::size_t samples() const { return samples_; }
  double first_time_s() const { return t_first_; }
  double last_time_s() const { return t_last_; }
  /// Complete revolutions seen (spinning), the last one counted when the dwell's last sample completes it.
  int complete_revolutions() const;
  /// Samples rejected as outliers so far (all of them once finish() was called).
  std::size_t outliers() const { return outliers_; }
  /// The time series breaks here (a gap): the revolution in progress is incomplete, so it does not count in
  /// the scatter between revolutions (its samples still enter the dwell's fit).
  void break_revolution();
  /// The revolution of gamma (rad) counted from a dwell's first gamma, in either sense of rotation: the
  /// periods of a spinning dwell's scatter, and so of any reduction that must cut a dwell where it does
  /// (identify/sensor_model_terms.cpp). The quotient is >= 0, so the conversion's truncation is its floor
  /// (std::floor is a call of libm on the baseline x86-64 and was 4 % of a calibration's time); a product by
  /// 1 / (2 pi), not a division (a sample within a rounding of a whole turn may fall in either revolution,
  /// the same one for every caller).
  static int revolution(double gamma_rad, double first_gamma_rad) {
    constexpr double kTurnsPerRad = 0.15915494309189533577;  // 1 / (2 pi)
    return static_cast<int>(std::abs(gamma_rad - first_gamma_rad) * kTurnsPerRad);
  }
  /// The method reducing this dwell (make_dwell_reduction's choice).
  const DwellReduction& reduction() const { return reduction_; }
  /// out's covariance, std_err, level, dof and revolutions from `scatter` about out's fit in time
  /// (out.scatter_t_mid, scatter_drift) with out.shape: the level is the scatter's variance per unit of the
  /// shape's, pooled over the gammas.
  static void state_level(DwellValues& out, const RevolutionSums& scatter);

 private:
  struct Pending {
    double t, gamma, value;
    int period;
    bool after_break;
    std::size_t index;  // the sample's number in the dwell
  };
  /// period: period_of(time_s, gamma_rad). basis: the outlier rule's detection basis at the sample (its first
  /// terms are a harmonic fit's basis), or null.
  void accumulate(double time_s, double gamma_rad, int period, const double* values, bool after_break,
                  const double* basis = nullptr);
  /// The period bookkeeping of a sample (or a run of samples) of `period`: the period before closes into the
  /// scatter (or is discarded, if broken) when this one begins; after_break marks this one broken.
  void enter_period(int period, bool after_break);
  /// A run of a block's samples in one period, by the sums the outlier rule formed (test_block).
  struct BlockRun {
    std::size_t count = 0;
    int period = 0;
    bool after_break = false;
    double t_scaled_sum = 0.0;
  };
  void test_block();
  void flush();
  void add_general(double time_s, double gamma_rad, const double* values);
  /// A block never holds more samples than this (a revolution of more samples is tested in parts): it bounds
  /// the memory of the outlier rule to a few MB whatever the plan.
  static constexpr std::size_t kMaxBlockSamples = std::size_t{1} << 15;
  int revolution_of(double gamma_rad) const { return revolution(gamma_rad, gamma_first_); }
  int period_of(double time_s, double gamma_rad) const;
  bool last_revolution_complete() const;
  double scaled_time(double time_s) const { return (time_s - t_first_) / duration_s_ - 0.5; }
  double scaled_mid_time() const;
  int detection_size() const;
  void detection_basis(double cos_gamma, double sin_gamma, double t_scaled, double* out) const;

  ReduceOptions options_;
  bool spinning_;
  std::size_t gammas_;  // how many values per column
  double duration_s_;
  double sweep_scaled_ = 0.0;  // the sweep's phase per unit of scaled time (sweep rate * planned duration)
  bool with_std_err_;
  DwellReduction reduction_;

  std::size_t samples_ = 0;
  double t_first_ = 0.0, t_last_ = 0.0;
  double gamma_first_ = 0.0, gamma_last_ = 0.0;
  bool finished_ = false;

  // Periods (with_std_err): revolutions of a spinning dwell, batches of a static hold's planned duration. A
  // period's values of column 0 enter the scatter when the next one begins; a revolution with a gap does not
  // (its fit would be of part of a turn), a batch does (a gap only shortens it).
  int period_ = 0;              // of the samples accumulated
  bool break_next_ = false;     // break_revolution() was called: the next sample follows a gap
  bool period_broken_ = false;  // the revolution in progress holds a gap: it does not count
  RevolutionSums scatter_;

  // Outlier rejection (docs/physics.md section 14): the block waiting to be tested, and the normal equations
  // of the dwell's fit (harmonics and drift; a static hold: mean and drift) on every sample accumulated so
  // far, outliers left out.
  bool robust_ = false;
  std::vector<Pending> pending_;
  int seen_revolution_ = 0;  // of the samples added
  int block_revolution_ = 0;
  Eigen::MatrixXd ref_normal_;
  Eigen::VectorXd ref_rhs_;
  double last_scale_ = 0.0;
  // A block whose outliers were settled without its scale (none can lie beyond the threshold: test_block)
  // keeps its residuals and absolute values, so that its scale is computed only if a short block needs it.
  bool last_scale_pending_ = false;
  std::vector<double> last_residuals_, last_abs_values_;
  double last_scale();
  std::size_t outliers_ = 0;
  std::vector<std::size_t> outlier_samples_;
  std::vector<double> scratch_basis_;  // the block's detection basis, sample by sample
  // The block's runs of samples in one period and their sums of b b' (lower triangles) and b v (test_block).
  std::vector<BlockRun> scratch_runs_;
  std::vector<double> scratch_run_normal_, scratch_run_rhs_;
};

}  // namespace gyrocal
