#pragma once
// The three ways of reducing one dwell (a static hold's mean, a spinning dwell's harmonic fit or window
// means), each a type of its own behind one interface (the concept DwellReductionMethod), held by
// DwellAccumulator (reduce/dwell_accumulator.hpp) in the variant DwellReduction. Each type owns only its own
// sums; what all three share (outlier rejection, counting revolutions, the scatter between revolutions, the
// heading's sweep) is written once, in DwellAccumulator. docs/architecture.md says why a variant.
//
// Every type sees a sample as (t_scaled, gamma_rad, values): t_scaled is the time scaled to about [-0.5, 0.5]
// over the planned dwell, (t - t_first) / planned_duration - 0.5, for well-conditioned drift columns;
// gamma_rad is the arm angle, rad, unwrapped. The values per gamma are evaluated at t_mid, on the same scale.
#include <concepts>
#include <cstddef>
#include <variant>
#include <vector>

#include <Eigen/Core>

namespace gyrocal {

struct ReduceOptions;  // reduce/dwell_accumulator.hpp
struct DwellValues;    // reduce/dwell_accumulator.hpp

/// The harmonic basis in the arm angle: 1, cos g, sin g, ..., cos Ng, sin Ng into out[0 .. 2N] (N = order;
/// cos kg and sin kg by angle addition from cos g and sin g). The harmonic fit's basis and, whatever the
/// method, the outlier rule's.
void harmonic_basis(double gamma_rad, int order, double* out);
/// harmonic_basis from cos gamma and sin gamma.
void harmonic_basis(double cos_gamma, double sin_gamma, int order, double* out);

/// normal += b b' on the lower triangle of an n x n column-major matrix: the normal equations' update of one
/// sample, the hot loop of a calibration. Each element's sum is the one a plain double loop forms (the same
/// products, added in the same order); the usual sizes (harmonic order 3: 7, 8, 10) are unrolled.
void add_outer_product(double* normal, const double* b, int n);

/// The sums of b b' over a run of samples for the harmonic basis with drift, b = (1, cos g, sin g, ..., cos
/// Ng, sin Ng, t_scaled) (2N + 2 terms), gathered as 6N + 4 moments instead of (N + 1)(2N + 3) products a
/// sample: a product of two harmonics is half the sum of the harmonics of their sum and difference (cos a cos
/// b = (cos(a - b) + cos(a + b)) / 2, ...), so the sums of cos k g and sin k g for k <= 2N, of t cos k g and
/// t sin k g for k <= N, and of t and t^2 give every element. The elements equal add_outer_product's sums up
/// to rounding (the harmonics come from one angle-addition recurrence; tests/test_dwell_reduction.cpp).
class HarmonicMoments {
 public:
  static constexpr int kMaxOrder = 12;  ///< ReduceOptions::harmonic_order's limit
  explicit HarmonicMoments(int order) : order_(order) {}
  /// One sample at cos g, sin g and t_scaled; writes its basis b (2N + 2 values, as harmonic_basis and then
  /// t_scaled) to `basis`.
  void add(double cos_gamma, double sin_gamma, double t_scaled, double* basis) {
    // The default order, unrolled by the compiler (a sample of every spinning dwell of a record comes here).
    if (order_ == 3) return add_order<3>(cos_gamma, sin_gamma, t_scaled, basis);
    add_order<0>(cos_gamma, sin_gamma, t_scaled, basis);
  }
  /// The samples added.
  double count() const { return count_; }
  /// The run's sums of b b' into `lower` (2N + 2 square, column-major; the lower triangle is written).
  void lower(double* lower) const;

 private:
  /// add() for order N (N = 0: the object's order, not known at compile time).
  template <int N>
  void add_order(double cos_gamma, double sin_gamma, double t_scaled, double* basis) {
    const int n = N > 0 ? N : order_, m = 2 * n;
    double c = cos_gamma, s = sin_gamma;
    basis[0] = 1.0;
    ++count_;
    t_ += t_scaled;
    tt_ += t_scaled * t_scaled;
    for (int k = 1; k <= m; ++k) {
      if (k > 1) {
        const double cn = c * cos_gamma - s * sin_gamma;
        s = s * cos_gamma + c * sin_gamma;
        c = cn;
      }
      cos_[k] += c;
      sin_[k] += s;
      if (k <= n) {
        basis[2 * k - 1] = c;
        basis[2 * k] = s;
        t_cos_[k] += t_scaled * c;
        t_sin_[k] += t_scaled * s;
      }
    }
    basis[m + 1] = t_scaled;
  }
  int order_;
  double count_ = 0.0, t_ = 0.0, tt_ = 0.0;
  double cos_[2 * kMaxOrder + 1] = {}, sin_[2 * kMaxOrder + 1] = {};  // index k: sum cos k g, sum sin k g
  double t_cos_[kMaxOrder + 1] = {}, t_sin_[kMaxOrder + 1] = {};      // index k: sum t cos k g, t sin k g
};

/// Per-revolution (or per-batch) values of column 0 at every gamma of a dwell, as sums for straight-line fits
/// in time and their cross products: their scatter is the level of the reduced values' covariance
/// (docs/calibration.md).
/// One period's values (one per gamma) at its mean scaled time: `index` numbers the period in its dwell (a
/// spinning dwell's revolution of gamma counted from its first sample; a static hold's batch).
struct PeriodValues {
  int index = 0;
  double t_scaled = 0.0;
  Eigen::VectorXd values;
};

struct RevolutionSums {
  /// The sweep's phase per unit of scaled time (0: none): then the fit in time is of 1, t, cos, sin of it
  /// (docs/physics.md section 15).
  double sweep = 0.0;
  Eigen::MatrixXd bb, bv;  // with a sweep: sums of b b' and b (v - v0)', b = (1, t, cos, sin)
  double n = 0, t = 0, tt = 0;
  Eigen::VectorXd v0;     // the first values: sums are of deviations from them (no cancellation)
  Eigen::VectorXd v, tv;  // sums of (v - v0) and t (v - v0)
  Eigen::MatrixXd vv;
  /// Every period added, in order (a few numbers a revolution): what the scatter of the output minus a
  /// model is taken from (relevel_from_periods). `index` is the number the next one added gets.
  std::vector<PeriodValues> periods;
  int index = 0;
  /// One period's values vi (one per gamma) at its mean scaled time ti.
  void add(double ti, const Eigen::VectorXd& vi);
  /// Covariance of the lines' predictions at t_mid (of the means without drift); NaN without enough
  /// revolutions.
  Eigen::MatrixXd covariance_at(double t_mid, bool drift) const;
  /// The parameters of the fit in time: the mean, the drift, the sweep's two.
  double parameters(bool drift) const { return 1.0 + (drift ? 1.0 : 0.0) + (sweep != 0.0 ? 2.0 : 0.0); }
};

/// A static hold: the mean of each column (no drift: held still, the output's drift is the noise's). Its
/// periods, for the scatter, are batches of time (DwellAccumulator cuts them); their means enter the scatter
/// at time 0, about their mean.
class StaticMean {
 public:
  /// gammas: the hold's gamma (one value; more are allowed and stay NaN). columns: values per sample.
  /// with_periods: also keep the batch's sum of column 0 (for the scatter).
  StaticMean(std::size_t gammas, int columns, bool with_periods);
  void add(double t_scaled, double gamma_rad, const double* values);
  /// `samples` samples at once whose values sum, per column, to rhs's one row (identify/model_terms.hpp: the
  /// model terms summed in closed form). No periods.
  void add_sums(std::size_t samples, const Eigen::MatrixXd& rhs);
  /// The batch's mean of column 0 into `scatter` (if it holds a sample); the batch starts again.
  void close_period(RevolutionSums& scatter);
  void discard_period();
  /// value[0] = the mean of `column`, samples[0] = the samples.
  void values(int column, double t_mid, DwellValues& out) const;
  /// gain[0] = 1 / samples (NaN elsewhere); the covariance is its diagonal.
  std::vector<double> white_noise_gain(double t_mid) const;
  Eigen::MatrixXd white_noise_covariance(double t_mid) const;
  /// Whether the values and the scatter carry a linear drift in time: never (a mean).
  bool fits_drift() const { return false; }
  std::size_t samples() const { return samples_; }

 private:
  std::size_t gammas_;
  bool with_periods_;
  std::size_t samples_ = 0;
  Eigen::VectorXd sum_;  // per column
  double batch_sum_ = 0.0;
  std::size_t batch_n_ = 0;
};

/// A spinning dwell: a least-squares fit of 1, cos k gamma, sin k gamma (k = 1..order) and, with drift,
/// t_scaled, to the whole dwell's samples (normal equations, lower triangle), evaluated at each gamma of the
/// plan at t_mid. Its periods are revolutions: per revolution, the same fit without drift on column 0.
class HarmonicFit {
 public:
  HarmonicFit(std::vector<double> gammas_rad, int order, bool linear_drift, int columns, bool with_periods);
  void add(double t_scaled, double gamma_rad, const double* values);
  /// add() with the basis at the sample already evaluated: b = basis(gamma_rad, t_scaled), basis_size()
  /// values (the outlier rule evaluates it for its own fit, whose first terms are these: DwellAccumulator).
  void add_basis(double t_scaled, const double* b, const double* values);
  /// A run of `samples` samples of the period in progress at once, by their sums: t_scaled_sum = sum of
  /// t_scaled, `lower` = sum b b' (basis_size() square, column-major, lower triangle read), `rhs` = sum b v'
  /// (basis_size() x columns, column-major). The outlier rule forms these sums for its own fit, whose basis
  /// this is (DwellAccumulator::test_block): the same as add_basis on each, but for the order of the sums'
  /// additions.
  void add_run(std::size_t samples, double t_scaled_sum, const double* lower, const double* rhs);
  /// `samples` samples at once, given by their sums: `normal` = sum b b' (basis_size() square, the lower
  /// triangle is read) and `rhs` = sum b v' (basis_size() x columns), b = basis(gamma, t_scaled) (identify/
  /// model_terms.hpp: the model terms summed in closed form). No periods.
  void add_sums(std::size_t samples, const Eigen::MatrixXd& normal, const Eigen::MatrixXd& rhs);
  /// The revolution's fit (without drift) at every gamma, at its mean time, into `scatter` if it holds at
  /// least two samples per parameter; the revolution's sums start again.
  void close_period(RevolutionSums& scatter);
  void discard_period();
  void values(int column, double t_mid, DwellValues& out) const;
  /// Per gamma: b' (Phi' Phi)^-1 b, b the basis at the gamma and t_mid.
  std::vector<double> white_noise_gain(double t_mid) const;
  /// B' (Phi' Phi)^-1 B: the values at different gammas share the fit's coefficients, so they correlate.
  Eigen::MatrixXd white_noise_covariance(double t_mid) const;
  bool fits_drift() const { return drift_; }
  std::size_t samples() const { return samples_; }
  /// The fit's basis at (gamma, t_scaled): 1, cos g, sin g, ..., cos Ng, sin Ng [, t_scaled].
  int basis_size() const { return 2 * order_ + 1 + (drift_ ? 1 : 0); }
  void basis(double gamma_rad, double t_scaled, double* out) const;

 private:
  std::vector<double> gammas_;
  int order_;
  bool drift_;
  int columns_;
  bool with_periods_;
  std::size_t samples_ = 0;
  /// The sums of the periods closed (or discarded) so far; with periods, those of the period in progress are
  /// in period_normal_ and period_rhs_, whose harmonic part is also the revolution's own fit (without drift,
  /// column 0): one outer product a sample serves both (docs/performance.md).
  Eigen::MatrixXd normal_;  // basis x basis
  Eigen::MatrixXd rhs_;     // basis x columns
  Eigen::MatrixXd period_normal_;
  Eigen::MatrixXd period_rhs_;
  /// normal_ and rhs_ with the period in progress added.
  Eigen::MatrixXd total_normal() const;
  Eigen::MatrixXd total_rhs() const;
  /// Moves the period's sums into normal_ and rhs_.
  void fold_period();
  std::size_t rev_samples_ = 0;
  double rev_time_sum_ = 0.0;
};

/// A spinning dwell: per gamma of the plan, the mean of the samples within +-window/2 of it (wrapped) and,
/// with drift, a straight line in time through them evaluated at t_mid. Its periods are revolutions: per
/// revolution, each window's plain mean of column 0; a revolution counts when it passed through every window.
class WindowMean {
 public:
  WindowMean(std::vector<double> gammas_rad, double window_deg, bool linear_drift, int columns,
             bool with_periods);
  void add(double t_scaled, double gamma_rad, const double* values);
  void close_period(RevolutionSums& scatter);
  void discard_period();
  /// Per gamma: the window's mean (or line at t_mid) and its samples; NaN and 0 for a window with none.
  void values(int column, double t_mid, DwellValues& out) const;
  /// Per gamma: 1/n (+ (t_mid - tbar)^2 / Stt with drift); NaN for an empty window.
  std::vector<double> white_noise_gain(double t_mid) const;
  /// Diagonal: the windows do not overlap, so their means do not correlate.
  Eigen::MatrixXd white_noise_covariance(double t_mid) const;
  bool fits_drift() const { return drift_; }
  std::size_t samples() const { return samples_; }

 private:
  std::vector<double> gammas_;
  double half_width_rad_;
  bool drift_;
  int columns_;
  bool with_periods_;
  std::size_t samples_ = 0;
  Eigen::MatrixXd sum_;                      // gamma x columns
  Eigen::MatrixXd tsum_;                     // gamma x columns: sum of t*value
  Eigen::VectorXd n_, t_, tt_;               // per gamma
  Eigen::VectorXd rev_sum_, rev_n_, rev_t_;  // per gamma, column 0, this revolution
};

/// The one interface of the three: whole-dwell sums (add), the period's values into the scatter
/// (close_period) or thrown away (discard_period, a revolution broken by a gap), the reduced values of a
/// column, the operator's white-noise gain and covariance (per unit variance of white noise on each sample),
/// and whether its fit carries a drift in time (the scatter's fit does as the values' does).
template <class M>
concept DwellReductionMethod = requires(M& m, const M& cm, double t, double gamma, const double* values,
                                        RevolutionSums& scatter, int column, DwellValues& out) {
  m.add(t, gamma, values);
  m.close_period(scatter);
  m.discard_period();
  cm.values(column, t, out);
  { cm.white_noise_gain(t) } -> std::same_as<std::vector<double>>;
  { cm.white_noise_covariance(t) } -> std::same_as<Eigen::MatrixXd>;
  { cm.fits_drift() } -> std::same_as<bool>;
  { cm.samples() } -> std::same_as<std::size_t>;
};
static_assert(DwellReductionMethod<StaticMean>);
static_assert(DwellReductionMethod<HarmonicFit>);
static_assert(DwellReductionMethod<WindowMean>);

/// One dwell's reduction, whichever method.
using DwellReduction = std::variant<StaticMean, HarmonicFit, WindowMean>;

/// The method of a dwell: a static hold (main axis stopped) is reduced by its mean whatever options.method; a
/// spinning dwell by options.method's fit (harmonic_order, linear_drift) or window means (window_deg,
/// linear_drift). gammas_rad: the plan's gammas of the dwell (a static hold: its one gamma). columns: values
/// per sample. with_periods: also keep column 0's sums per revolution (or batch) for the scatter.
DwellReduction make_dwell_reduction(const ReduceOptions& options, std::vector<double> gammas_rad,
                                    bool is_static, int columns, bool with_periods);

}  // namespace gyrocal
