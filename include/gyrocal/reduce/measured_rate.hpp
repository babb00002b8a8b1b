#pragma once
// The main axis' motion as its encoder measures it through a dwell (docs/calibration.md, "The rate the
// channels follow"): a smoothing cubic spline of the main angle against the sample grid, fitted streaming, so
// that the model terms can be evaluated at the angle, rate and angular acceleration the arm really had
// at each sample (a drive's rate ripple moves an accelerometer's centripetal input at first order) rather
// than on the dwell's constant-rate line. Physics-free: angles in rad, times in s.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace gyrocal {

/// The main axis at one instant, from the measured motion.
struct MeasuredState {
  double angle_rad = 0.0;     ///< theta, unwrapped on the dwell's reference
  double rate_rad_s = 0.0;    ///< d theta / dt
  double accel_rad_s2 = 0.0;  ///< d2 theta / dt2
};

/// One phase (the samples between two gaps: the encoder's phase is measured afresh after a gap) as a uniform
/// cubic B-spline: theta(x) = reference(x) + sum_k c_k B_k((x - first_knot) / knot_interval).
struct MeasuredPhase {
  double first_knot_s = 0.0;
  std::vector<double> coefficients;  ///< rad
  /// The phase's own least-squares line of the same deviations: dev(x) = line_at + line_rate (x -
  /// first_knot).
  double line_at_rad = 0.0, line_rate_rad_s = 0.0;
};

/// A dwell's measured main-axis motion (empty `phases`: none was fitted, e.g. a static hold or a planned
/// dwell). The fit's abscissa x of the i-th sample of a stretch is the stretch's first time stamp plus i
/// sample intervals of the plan: the stamps' jitter and rounding are the clock's reading error, not the
/// sampling instant (docs/calibration.md), so they do not enter the fit.
struct MeasuredMotion {
  double knot_interval_s = 0.0;  ///< h, s
  double grid_interval_s = 0.0;  ///< the planned sample interval the abscissa advances by per sample, s
  double origin_s = 0.0;         ///< reference(x) = origin_rad + reference_rate (x - origin_s)
  double origin_rad = 0.0;
  double reference_rate_rad_s = 0.0;
  std::vector<MeasuredPhase> phases;
  std::vector<std::size_t>
      stretch_phase;  ///< per TimeStretch of the dwell: its phase (filled by the reducer)

  std::size_t samples = 0;
  /// RMS of the readings about the spline (quantisation, jitter of the angle), rad.
  double residual_rad = 0.0;
  /// Standard errors the readings' scatter leaves on the measured angle and rate at an interior point of the
  /// longest phase (the spline's own noise; the rate's is what it adds to a centripetal force), rad, rad/s.
  double angle_noise_rad = 0.0, rate_noise_rad_s = 0.0;
  /// The largest |deviation| of the spline from its phase's straight line (angle, rate, acceleration): what a
  /// constant-rate model misses.
  double max_angle_deviation_rad = 0.0, max_rate_deviation_rad_s = 0.0, max_accel_rad_s2 = 0.0;
  /// The F-test of the spline against the lines: the drop of the residual sum of squares in units of the
  /// scatter, its degrees of freedom, and whether it exceeds dof + 8 sqrt(2 dof) (a ripple is resolved; white
  /// noise alone passes that with probability below 1e-10).
  double chi2 = 0.0, dof = 0.0;
  bool resolved = false;
  /// The largest |second difference| of successive readings on the grid, rad: at least one count of a
  /// quantised encoder (the readings are whole counts, a smooth motion's second difference is far below one),
  /// otherwise the scatter's extremes.
  double count_bound_rad = 0.0;
  /// The spline departs from the line by more than 0.6 x count_bound: a quantised encoder read at a rate
  /// nearly commensurate with its count makes its rounding error a slow sawtooth of at most half a count,
  /// which the F-test alone would take for a motion (a false alarm found at one rate in twenty).
  bool quanta_resolved = false;

  bool empty() const { return phases.empty(); }
  /// The main axis at abscissa x in phase p (clamped to the phase's knots).
  MeasuredState at(std::size_t phase, double x_s) const;
};

/// Streaming fit of MeasuredMotion: begin_phase() at the measured part's first sample and after every gap,
/// add() every sample, finish() once. Memory: 5 numbers per knot.
class MeasuredMotionFit {
 public:
  /// The knot interval: h = max(knot_interval_s, 8 sample intervals), shortened so that the planned span
  /// (the measured part's planned duration; 0: none) holds a whole number of intervals. theta is fitted as
  /// its deviation from reference(x). The reducer takes a quarter of a revolution of gamma
  /// (kMeasuredKnotRevolutions): the readings' scatter near the revolution's harmonics, which a reduced value
  /// picks up through the centripetal force, is what the measured rate must not carry (a cubic B-spline's
  /// response vanishes at multiples of 1/h: a quarter revolution puts the first at the fourth harmonic,
  /// beyond the fit's third), while a rate change over a revolution is followed.
  MeasuredMotionFit(double grid_interval_s, double origin_s, double origin_rad, double reference_rate_rad_s,
                    double knot_interval_s, double span_s = 0.0);
  void begin_phase(double x_s);
  void add(double x_s, double theta_rad);
  std::size_t phase() const { return phases_.empty() ? 0 : phases_.size() - 1; }
  /// The fitted motion (folds the moments of the intervals still open: call it once, at the end).
  MeasuredMotion finish();

 private:
  struct Phase {
    double first_knot = 0.0;
    std::vector<double> band;  // 4 per knot: M(k, k + m), m = 0..3
    std::vector<double> rhs;
    double n = 0, sx = 0, sxx = 0, sy = 0, sxy = 0, syy = 0;
    double x1 = 0, y1 = 0, x2 = 0, y2 = 0;  // the last two samples
    // The knot interval the samples now go to, and their moments there: sum t^k (k = 0..6) and sum t^k y
    // (k = 0..3), t the place in the interval. The B-splines are cubics in t, so these give the interval's
    // terms of `band` and `rhs` exactly (up to rounding) when it is left (fold), at a fraction of evaluating
    // the basis at every sample (it was a sixth of a calibration's reducer, docs/performance.md).
    std::size_t interval = 0;
    double t_moment[7] = {}, ty_moment[4] = {};
  };
  /// Adds the current interval's moments of `p` into its band and right-hand side, and clears them.
  static void fold(Phase& p);
  MeasuredMotion out_;
  double inverse_knot_interval_ = 0.0;
  double span_s_ = 0.0;  ///< the planned span (0: none)
  std::vector<Phase> phases_;
};

/// The spline's knot interval in revolutions of gamma (MeasuredMotionFit, at least 8 sample intervals): a
/// quarter of a revolution. The model terms' exactness on a rippling drive is the spline's approximation of
/// the ripple: on the tests' rig-like records (a ripple of 2e-4 at 0.37 Hz, 6 and 12 rad/s, 50 Hz, 8
/// revolutions, 2^32-count encoders; tests/test_accelerometer_rig.cpp) half a revolution with a floor of 16
/// samples missed the specific force by up to 3e-5 g a sample and left 6e-3 ug/g^2 on Kio and 7e-3 urad on
/// delta_p; a quarter with a floor of 8 leaves 1.0e-3 ug/g^2 on Kip, 5e-4 urad on delta_p and below 1.3e-4
/// of their units on the others. An eighth with a floor of 4 left 2.6e-4 urad on delta_p and below 6e-5 on
/// the others, but then the F-test took a smooth simulated record with large machine errors for a ripple
/// (tests/test_model_terms_fourier.cpp): not taken until that is understood. The spline's noise grows as
/// h^-3/2; an accelerometer's stated std is taken from the scatter of the output minus the model, which
/// holds it (docs/accelerometer.md).
inline constexpr double kMeasuredKnotRevolutions = 0.25;

// Inline: a sample of every spinning dwell of a record goes through it (a call a sample was measurable).
inline void MeasuredMotionFit::add(double x_s, double theta_rad) {
  if (phases_.empty()) begin_phase(x_s);
  Phase& p = phases_.back();
  const double y = theta_rad - out_.origin_rad - out_.reference_rate_rad_s * (x_s - out_.origin_s);
  const double x = x_s - p.first_knot;
  // x / h by a product (a division's latency was a third of this function's time): a sample within a
  // rounding of a knot may go to the interval on the other side, where the B-splines take the same values.
  const double u = std::max(0.0, x * inverse_knot_interval_);
  const auto j = static_cast<std::size_t>(static_cast<std::int64_t>(u));  // u >= 0: truncation = floor
  if (j != p.interval) {
    fold(p);
    p.interval = j;
  }
  const double t = u - static_cast<double>(j), t2 = t * t, t3 = t2 * t;
  double* tm = p.t_moment;
  tm[0] += 1.0;
  tm[1] += t;
  tm[2] += t2;
  tm[3] += t3;
  tm[4] += t2 * t2;
  tm[5] += t2 * t3;
  tm[6] += t3 * t3;
  double* ty = p.ty_moment;
  ty[0] += y;
  ty[1] += t * y;
  ty[2] += t2 * y;
  ty[3] += t3 * y;
  // Second differences of readings evenly spaced on the grid (a dropped row breaks the spacing).
  if (p.n >= 2 && std::abs((x - p.x1) - (p.x1 - p.x2)) < 1e-6 * out_.grid_interval_s)
    out_.count_bound_rad = std::max(out_.count_bound_rad, std::abs((y - p.y1) - (p.y1 - p.y2)));
  p.x2 = p.x1, p.y2 = p.y1, p.x1 = x, p.y1 = y;
  p.n += 1;
  p.sx += x;
  p.sxx += x * x;
  p.sy += y;
  p.sxy += x * y;
  p.syy += y * y;
  ++out_.samples;
}

}  // namespace gyrocal
