#pragma once
// The reduction of one dwell: a linear operator from a dwell's samples to one value per gamma of the
// plan. The same operator reduces the gyro output and, in the identify stage, the model's channels
// (omega_I and the drift regressors) evaluated on the dwell's samples, so that
//   reduce(W) = reduce(omega_I) + sum_j c_j reduce(x_j)
// holds exactly whatever harmonics the machine's errors add.
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace gyrocal {

/// How a dwell is reduced. Defaults as stated; IsValid() checks them.
struct ReduceOptions {
  enum class Method {
    kHarmonicFit,  ///< least-squares fit of a harmonic series in gamma plus a linear drift in time (default)
    kWindowMean,   ///< mean of the samples within +-window/2 of each gamma
  };
  Method method = Method::kHarmonicFit;
  int harmonic_order = 3;            ///< harmonic fit: orders 0..harmonic_order in gamma
  bool linear_drift = true;          ///< harmonic fit and window mean: a linear drift in time
  double window_deg = 10.0;          ///< window mean: full width of the window around each gamma, deg
  double beta_tolerance_deg = 1e-3;  ///< a dwell's beta stays within this of its first value, deg
  double rate_tolerance = 1e-3;  ///< relative to the planned rate: a spinning dwell's sample-to-sample rate
  double static_rate_tolerance_rad_s = 0.01;  ///< below this the main axis (or platform) counts as stopped
  int static_batches = 16;                    ///< a static hold's standard error from this many batch means
  /// The model's channels (identify/channels.hpp) are smooth in gamma (harmonics up to ~6), so they are
  /// evaluated on every k-th sample of a dwell with k chosen to keep at least this many samples per
  /// revolution (and 64 per static hold); the dwell's first and last samples are always in. 0: every sample.
  int model_samples_per_revolution = 32;

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
};

/// Accumulates one dwell's samples (streaming, memory independent of the dwell's length) and reduces them.
/// Spinning dwell: the values at each gamma of `gammas_rad`. Static hold: one value (the mean).
class DwellAccumulator {
 public:
  /// columns: how many value columns each sample carries (1 for the gyro output, more for model channels).
  /// planned_duration_s: the planned length of the measured part (> 0), to scale time and size batches.
  /// with_std_err: also compute the standard errors of column 0 (scatter between revolutions or batches).
  DwellAccumulator(const ReduceOptions& options, std::vector<double> gammas_rad, bool is_static, int columns,
                   double planned_duration_s, bool with_std_err);

  /// One sample at time t (s) and arm angle gamma (rad, unwrapped: it must progress monotonically while
  /// spinning), with `columns` values.
  void add(double time_s, double gamma_rad, const double* values);

  /// The reduced values of column `column`, evaluated at the dwell's mid-time.
  DwellValues finish(int column) const;

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
  /// Complete revolutions seen (spinning).
  int complete_revolutions() const { return revolution_; }

 private:
  void close_revolution();
  int basis_size() const;
  void basis(double gamma_rad, double t_scaled, double* out) const;

  ReduceOptions options_;
  std::vector<double> gammas_;
  bool static_;
  int columns_;
  double duration_s_;
  bool with_std_err_;

  std::size_t samples_ = 0;
  double t_first_ = 0.0, t_last_ = 0.0;
  double gamma_first_ = 0.0;
  int revolution_ = 0;

  // Harmonic fit over the whole dwell: normal equations of the (well-conditioned) harmonic basis.
  Eigen::MatrixXd normal_;  // basis x basis
  Eigen::MatrixXd rhs_;     // basis x columns
  // Per revolution (std err): the same fit without drift, on column 0 only.
  Eigen::MatrixXd rev_normal_;
  Eigen::VectorXd rev_rhs_;
  std::size_t rev_samples_ = 0;
  double rev_time_sum_ = 0.0;
  // Window mean: per gamma, sums over the whole dwell (with drift: also t and t^2) and per revolution.
  Eigen::MatrixXd window_sum_;                                             // gamma x columns
  Eigen::MatrixXd window_tsum_;                                            // gamma x columns: sum of t*value
  Eigen::Vector<double, Eigen::Dynamic> window_n_, window_t_, window_tt_;  // per gamma
  Eigen::VectorXd rev_window_sum_, rev_window_n_, rev_window_t_;           // per gamma, column 0
  // Per-revolution (or batch) values of column 0 at every gamma, as sums for straight-line fits in time
  // and their cross products.
  struct RevolutionSums {
    double n = 0, t = 0, tt = 0;
    Eigen::VectorXd v0;     // the first values: sums are of deviations from them (no cancellation)
    Eigen::VectorXd v, tv;  // sums of (v - v0) and t (v - v0)
    Eigen::MatrixXd vv;
    void add(double ti, const Eigen::VectorXd& vi);
    /// Covariance of the lines' predictions at t_mid (of the means without drift); NaN without enough
    /// revolutions.
    Eigen::MatrixXd covariance_at(double t_mid, bool drift) const;
  };
  RevolutionSums trend_;
  // Static hold: sums per column, and batch means of column 0.
  Eigen::VectorXd static_sum_;
  double batch_sum_ = 0.0;
  std::size_t batch_n_ = 0;
  int batch_index_ = 0;
  RevolutionSums batches_;
};

}  // namespace gyrocal
