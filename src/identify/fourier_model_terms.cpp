// The Fourier route of the per-dwell model route (identify/dwell_model_route.hpp): a dwell's model columns as
// a two-dimensional Fourier series in the two joint angles, summed over its samples in closed form
// (docs/calibration.md, "The model's side of each position"). For any sensor's columns.
#include <algorithm>
#include <cmath>
#include <complex>

#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/dwell_model_route.hpp"
#include "gyrocal/model/machine_errors.hpp"
#include "gyrocal/record/increments.hpp"

namespace gyrocal {

namespace {

using Complex = std::complex<double>;

/// a b, as std::complex's operator* gives it for finite operands, without the recovery of infinite results
/// that C's Annex G asks of it (GCC checks every product for NaN and calls __muldc3): in the closed forms'
/// inner loops that check was ~100 instructions a product, half of the model terms' time after the reading.
/// The model terms and their sums are finite.
inline Complex times(const Complex& a, const Complex& b) {
  return {a.real() * b.real() - a.imag() * b.imag(), a.real() * b.imag() + a.imag() * b.real()};
}

/// x reduced to [-pi, pi) with 2 pi split in two parts, so that an angle of thousands of revolutions keeps
/// its phase to ~1e-16 rad (std::remainder by the rounded 2 pi would lose 2.4e-16 rad a turn).
double reduce_angle(double x) {
  constexpr double kTwoPiHi = 6.28318530717958623200e+00;  // 2 pi rounded to double
  constexpr double kTwoPiLo = 2.44929359829470635445e-16;  // 2 pi - kTwoPiHi
  const double k = std::nearbyint(x / (2.0 * kPi));
  return std::fma(-k, kTwoPiLo, std::fma(-k, kTwoPiHi, x));
}

/// sum_{i<n} e^{j f i} and sum_{i<n} i e^{j f i} in closed form, accurate for every f (near multiples of
/// 2 pi too): e^{j (n-1) x} D and e^{j (n-1) x} ((n-1)/2 D - j/2 D'), x = f/2 reduced to [-pi/2, pi/2],
/// D = sin(n x) / sin(x), D' = dD/dx (by its Taylor series where n |x| < 1e-3: no cancellation).
std::pair<Complex, Complex> power_sums(double f, double n) {
  const double x = 0.5 * std::remainder(f, 2.0 * kPi);
  double a, da;
  if (std::abs(n * x) < 1e-3) {
    const double n2 = n * n, x2 = x * x;
    a = n * (1.0 - (n2 - 1.0) * x2 / 6.0 + (n2 - 1.0) * (3.0 * n2 - 7.0) * x2 * x2 / 360.0);
    da = n * (-(n2 - 1.0) * x / 3.0 + (n2 - 1.0) * (3.0 * n2 - 7.0) * x2 * x / 90.0);
  } else {
    const double s = std::sin(x), c = std::cos(x), sn = std::sin(n * x), cn = std::cos(n * x);
    a = sn / s;
    da = (n * cn * s - sn * c) / (s * s);
  }
  const Complex rotation = std::polar(1.0, (n - 1.0) * x);
  return {rotation * a, rotation * Complex(0.5 * (n - 1.0) * a, -0.5 * da)};
}

/// The highest harmonic of any of the configured errors' series (0 without any).
int highest_error_harmonic_of(const CentrifugeErrors& errors) {
  int highest = 0;
  for (const MachineErrorField& f : machine_error_fields()) {
    if (f.kind != MachineErrorKind::kSeries) continue;
    for (const HarmonicTerm& t : (errors.*f.series).terms)
      if (t.amplitude != 0.0) highest = std::max(highest, std::abs(t.harmonic));
  }
  return highest;
}

/// A stretch of evenly spaced samples of a dwell: the first one's time and joint angles, the interval.
struct Run {
  double first_time_s, interval_s;
  std::size_t count;
  double main_rad, counter_rad;
};

std::vector<Run> runs_of(const Dwell& d) {
  std::vector<Run> runs;
  if (d.stretches.empty()) {
    if (d.samples > 0)
      runs.push_back(
          {d.first_time_s, d.sample_interval_s, d.samples, d.main.at_first_rad, d.counter.at_first_rad});
  } else {
    for (const TimeStretch& s : d.stretches)
      if (s.count > 0)
        runs.push_back({s.first_time_s, s.interval_s, s.count, s.main_at_first_rad, s.counter_at_first_rad});
  }
  return runs;
}

/// The model terms of one dwell as a two-dimensional Fourier series in the main angle theta and the counter
/// platform's angle psi_r, on which they depend alone during a dwell (the rates and beta are the dwell's):
///   c(theta, psi) = sum_{|n|, |m| <= H} C_nm e^{j (n theta + m psi)},
/// C_nm from the model terms on a (2H+1) x (2H+1) grid of angles (the discrete Fourier transform). On a
/// stretch's samples theta and psi advance by constant steps, so every sum the reduction operator takes of
/// the model terms times its basis (1, cos k gamma, sin k gamma with gamma = -psi, the scaled time) is a sum
/// of geometric series in closed form (power_sums): the cost depends on H and the stretches, not the samples.
/// docs/calibration.md, "The model's side of each position", states the bound.
class FourierModelTerms {
 public:
  FourierModelTerms(const DwellModelTermsEvaluator& evaluate, int column_count, int harmonics)
      : h_(harmonics),
        size_(2 * harmonics + 1),
        columns_(column_count),
        coefficients_(static_cast<std::size_t>(size_ * size_ * column_count)) {
    const auto columns = static_cast<std::size_t>(columns_);
    const auto m = static_cast<std::size_t>(size_);
    // Samples on the grid theta_a = 2 pi a / M, psi_b = 2 pi b / M.
    std::vector<double> grid(m * m * columns);
    for (std::size_t a = 0; a < m; ++a)
      for (std::size_t b = 0; b < m; ++b)
        evaluate(2.0 * kPi * static_cast<double>(a) / size_, 2.0 * kPi * static_cast<double>(b) / size_,
                 &grid[(a * m + b) * columns]);
    // e^{-j 2 pi q / M} / M, q = 0 .. M-1.
    std::vector<Complex> twiddle(m);
    for (std::size_t q = 0; q < m; ++q)
      twiddle[q] = std::polar(1.0, -2.0 * kPi * static_cast<double>(q) / size_) / static_cast<double>(size_);
    const auto w_at = [&](long q) { return twiddle[static_cast<std::size_t>((q % size_ + size_) % size_)]; };
    // Along theta, then along psi: F[n][b] = 1/M sum_a c_ab e^{-j n theta_a}, C[n][m] = 1/M sum_b F[n][b]
    // e^{-j m psi_b}. The terms are real, so C[-n][-m] = conj(C[n][m]): the rows n >= 0 are transformed,
    // the others are their conjugates (half the work).
    std::vector<Complex> along(m * m * columns);
    for (int n = 0; n <= h_; ++n)
      for (std::size_t b = 0; b < m; ++b) {
        Complex* out = &along[(index(n) * m + b) * columns];
        for (std::size_t a = 0; a < m; ++a) {
          const Complex w = w_at(n * static_cast<long>(a));
          const double* c = &grid[(a * m + b) * columns];
          for (std::size_t col = 0; col < columns; ++col) out[col] += w * c[col];
        }
      }
    for (int n = 0; n <= h_; ++n)
      for (int k = -h_; k <= h_; ++k) {
        Complex* out = &coefficients_[(index(n) * m + index(k)) * columns];
        for (std::size_t b = 0; b < m; ++b) {
          const Complex w = w_at(k * static_cast<long>(b));
          const Complex* f = &along[(index(n) * m + b) * columns];
          for (std::size_t col = 0; col < columns; ++col) out[col] += times(w, f[col]);
        }
      }
    for (int n = -h_; n < 0; ++n)
      for (int k = -h_; k <= h_; ++k) {
        Complex* out = &coefficients_[(index(n) * m + index(k)) * columns];
        const Complex* mirror = &coefficients_[(index(-n) * m + index(-k)) * columns];
        for (std::size_t col = 0; col < columns; ++col) out[col] = std::conj(mirror[col]);
      }
  }

  /// Each coefficient C_nm times the mean over a sample's interval of e^{j (n theta + m psi)} relative to its
  /// value at the stamp (interval_mean_factor), the angles turning at the main and counter rates wm, wc.
  void average_over_interval(double wm, double wc, double interval_s) {
    const auto columns = static_cast<std::size_t>(columns_);
    for (int n = -h_; n <= h_; ++n)
      for (int k = -h_; k <= h_; ++k) {
        // n wm + k wc, as add_run writes it (no loss where wc ~ -wm).
        const double f = static_cast<double>(n) * (wm + wc) + static_cast<double>(k - n) * wc;
        const Complex factor = interval_mean_factor(f, interval_s);
        Complex* c = &coefficients_[(index(n) * static_cast<std::size_t>(size_) + index(k)) * columns];
        for (std::size_t col = 0; col < columns; ++col) c[col] = times(c[col], factor);
      }
  }

  /// Per column: the sum of |C_nm| over the outer quarter of the band (max(|n|, |m|) > 3H/4), and over all
  /// of it; the number of coefficients in that quarter.
  int tails(std::vector<double>& outer, std::vector<double>& all) const {
    const int columns = columns_;
    outer.assign(static_cast<std::size_t>(columns), 0.0);
    all.assign(static_cast<std::size_t>(columns), 0.0);
    int count = 0;
    for (int n = -h_; n <= h_; ++n)
      for (int k = -h_; k <= h_; ++k) {
        const bool out = 4 * std::max(std::abs(n), std::abs(k)) > 3 * h_;
        count += out ? 1 : 0;
        const Complex* c = at(n, k);
        for (int col = 0; col < columns; ++col) {
          // |C| without std::abs's hypot (its care for overflow costs ~20 ns; a term here is far from it).
          const double size = std::sqrt(std::norm(c[col]));
          all[static_cast<std::size_t>(col)] += size;
          if (out) outer[static_cast<std::size_t>(col)] += size;
        }
      }
    return count;
  }

  /// Adds to q[k][col] (k = 0 .. order) the sum over the run's samples of e^{j k gamma_i} c_i, and to
  /// tsum[col] that of tau_i c_i with tau_i = alpha + beta i (the scaled time).
  void add_run(const Dwell& d, const Run& r, int order, double alpha, double beta, std::vector<Complex>& q,
               std::vector<double>& tsum) const {
    const int columns = columns_;
    const double n_samples = static_cast<double>(r.count);
    const double wm = d.main.rate_rad_s, wc = d.counter.rate_rad_s;
    const double theta = reduce_angle(r.main_rad), psi = reduce_angle(r.counter_rad);
    const int mk = h_ + order;  // psi's harmonics m - k, |m - k| <= H + order
    const auto width = static_cast<std::size_t>(2 * mk + 1);
    std::vector<Complex> p(static_cast<std::size_t>(size_) * width), p1(p.size());
    for (int n = -h_; n <= h_; ++n)
      for (int k = -mk; k <= mk; ++k) {
        // n wm + k wc, written so that the near-cancelling n (wm + wc) (wc ~ -wm) is not lost.
        const double f =
            (static_cast<double>(n) * (wm + wc) + static_cast<double>(k - n) * wc) * r.interval_s;
        const auto [s0, s1] = power_sums(f, n_samples);
        const Complex phase = std::polar(1.0, static_cast<double>(n) * theta + static_cast<double>(k) * psi);
        const std::size_t i = index(n) * width + static_cast<std::size_t>(k + mk);
        p[i] = phase * s0;
        p1[i] = phase * (alpha * s0 + beta * s1);
      }
    for (int n = -h_; n <= h_; ++n)
      for (int m = -h_; m <= h_; ++m) {
        const Complex* c = at(n, m);
        // e^{j k gamma} = e^{-j k psi}: the harmonic m - k of psi.
        for (int k = 0; k <= order; ++k) {
          const Complex w = p[index(n) * width + static_cast<std::size_t>(m - k + mk)];
          Complex* out = &q[static_cast<std::size_t>(k * columns)];
          for (int col = 0; col < columns; ++col) out[col] += times(c[col], w);
        }
        const Complex w1 = p1[index(n) * width + static_cast<std::size_t>(m + mk)];
        for (int col = 0; col < columns; ++col)
          tsum[static_cast<std::size_t>(col)] += times(c[col], w1).real();
      }
  }

 private:
  std::size_t index(int n) const { return static_cast<std::size_t>(n + h_); }
  const Complex* at(int n, int m) const {
    return &coefficients_[(index(n) * static_cast<std::size_t>(size_) + index(m)) *
                          static_cast<std::size_t>(columns_)];
  }
  int h_;
  int size_;
  int columns_;
  std::vector<Complex> coefficients_;  // [n][m][column]
};

/// The Fourier route for one dwell (FourierModelTerms) into `acc`, when its check holds, column by column:
/// the model terms' coefficients in the outer quarter of the band (max(|n|, |m|) > 3H/4) sum to at most
///   e x (coefficients in that quarter) / (2H + 1),
/// the flat floor the model's own rounding e leaves on a grid's transform: for a regressor (g, g^2)
/// kRegressorRounding x max(1, the sum of all its |C_nm|); for a rate (deg/h) kRateRounding x (|main rate| +
/// |counter rate|) in deg/h, since the rates are differences of terms that large (the platform turns back
/// what the arm turns; measured on omega_S with 1e-4 wobbles: ~4e-10 deg/h a ring of the band, 4.9e-9 deg/h
/// over the outer quarter at H = 28, against 2e-8 allowed). A decaying series falls below this floor well
/// inside the band. H is chosen from the configured errors: 8 x their highest harmonic + 4 (at least 12),
/// doubled once if the check fails; beyond kMaxFourierHarmonic, or if it still fails, or where every sample
/// costs less, false (the caller takes every sample). `route` says what was done.
constexpr double kRegressorRounding = 2e-15;
constexpr double kRateRounding = 2e-16;
constexpr int kMaxFourierHarmonic = 64;

}  // namespace

int fourier_harmonics(const CentrifugeModel& model) {
  return std::max(12, 8 * highest_error_harmonic_of(model.errors()) + 4);
}

bool reduce_dwell_by_fourier(const CentrifugeModel& model, const Dwell& d, const ReduceOptions& options,
                             DwellAccumulator& acc, int columns, const std::vector<bool>& rate_column,
                             const DwellModelTermsEvaluator& evaluate, DwellModelTermsRoute& route,
                             double interval_s) {
  const std::vector<Run> runs = runs_of(d);
  if (runs.empty()) return false;
  // A static hold whose encoders' lines stand still (both rates exactly 0, as a noise-free or resting
  // encoder gives them): every sample of a run is at the run's joints, so the series of its model terms is
  // their value there; the sum over the run is that value times its count (and an increment's mean over its
  // interval is the same value). Exact, at one evaluation a run instead of a grid of (2H + 1)^2: an IMU
  // takes its static holds' model terms some fifty times over (channels x its error derivatives and steps).
  if (d.is_static && d.main.rate_rad_s == 0.0 && d.counter.rate_rad_s == 0.0) {
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(1, columns);
    std::vector<double> v(static_cast<std::size_t>(columns));
    // The series is its constant term alone: no tail; its size the largest value of a run.
    route.outer_tail.assign(static_cast<std::size_t>(columns), 0.0);
    route.scale.assign(static_cast<std::size_t>(columns), 0.0);
    std::size_t total = 0;
    for (const Run& r : runs) {
      evaluate(r.main_rad, r.counter_rad, v.data());
      for (int c = 0; c < columns; ++c) {
        const auto k = static_cast<std::size_t>(c);
        rhs(0, c) += static_cast<double>(r.count) * v[k];
        route.scale[k] = std::max(route.scale[k], std::abs(v[k]));
      }
      total += r.count;
    }
    const Run& last = runs.back();
    acc.add_sums(runs.front().first_time_s,
                 last.first_time_s + static_cast<double>(last.count - 1) * last.interval_s, total,
                 Eigen::MatrixXd(), rhs);
    route.fourier = true;
    route.harmonics = 0;
    route.operator_gain = acc.white_noise_gain();
    return true;
  }
  const int order = d.is_static ? 0 : options.harmonic_order;
  int harmonics = fourier_harmonics(model);
  // The closed forms cost about (2H+1)^2 (order + 2) columns operations a stretch; every sample about a
  // model evaluation (~1000 operations) a sample: the cheaper route is taken.
  std::size_t total = 0;
  for (const Run& r : runs) total += r.count;
  for (int attempt = 0; attempt < 2 && harmonics <= kMaxFourierHarmonic; ++attempt, harmonics *= 2) {
    const double width = 2.0 * harmonics + 1.0;
    const double closed_cost =
        width * width * (static_cast<double>(runs.size()) * (order + 2.0) * columns + 1000.0);
    if (closed_cost > 1000.0 * static_cast<double>(total)) return false;
    FourierModelTerms fourier(evaluate, columns, harmonics);
    std::vector<double> outer, all;
    const double outer_count = fourier.tails(outer, all);
    const double rates_deg_h =
        (std::abs(d.main.rate_rad_s) + std::abs(d.counter.rate_rad_s)) * kRadPerSecToDegPerHour;
    bool holds = true;
    for (int c = 0; c < columns; ++c) {
      const bool rate = rate_column[static_cast<std::size_t>(c)];
      const double floor = rate ? kRateRounding * std::max(1.0, rates_deg_h)
                                : kRegressorRounding * std::max(1.0, all[static_cast<std::size_t>(c)]);
      holds = holds && outer[static_cast<std::size_t>(c)] <= floor * outer_count / width;
    }
    route.harmonics = harmonics;
    route.outer_tail = outer;
    route.scale = all;
    if (!holds) continue;
    if (interval_s > 0.0) fourier.average_over_interval(d.main.rate_rad_s, d.counter.rate_rad_s, interval_s);
    // Sums over every run's samples: q[k][col] = sum e^{j k gamma} c, tsum[col] = sum tau c; and the basis'
    // own sums for the normal matrix: e0[p] = sum e^{j p gamma} (p <= 2 order), e1[p] = sum tau e^{j p
    // gamma}, tt = sum tau^2.
    const double t_first = runs.front().first_time_s;
    const Run& last = runs.back();
    const double t_last = last.first_time_s + static_cast<double>(last.count - 1) * last.interval_s;
    std::vector<Complex> q(static_cast<std::size_t>((order + 1) * columns));
    std::vector<double> tsum(static_cast<std::size_t>(columns), 0.0);
    std::vector<Complex> e0(static_cast<std::size_t>(2 * order + 1)), e1(static_cast<std::size_t>(order + 1));
    double tt = 0.0;
    for (const Run& r : runs) {
      const double n = static_cast<double>(r.count);
      const double alpha = DwellAccumulator::scaled_time(r.first_time_s, t_first, d.planned_duration_s);
      const double beta = r.interval_s / d.planned_duration_s;
      fourier.add_run(d, r, order, alpha, beta, q, tsum);
      const double gamma0 = -reduce_angle(r.counter_rad), step = -d.counter.rate_rad_s * r.interval_s;
      for (int p = 0; p <= 2 * order; ++p) {
        const auto [s0, s1] = power_sums(p * step, n);
        const Complex phase = std::polar(1.0, p * gamma0);
        e0[static_cast<std::size_t>(p)] += phase * s0;
        if (p <= order) e1[static_cast<std::size_t>(p)] += phase * (alpha * s0 + beta * s1);
      }
      tt += n * alpha * alpha + alpha * beta * n * (n - 1.0) +
            beta * beta * (n - 1.0) * n * (2.0 * n - 1.0) / 6.0;
    }
    if (d.is_static) {
      Eigen::MatrixXd rhs(1, columns);
      for (int c = 0; c < columns; ++c) rhs(0, c) = q[static_cast<std::size_t>(c)].real();
      acc.add_sums(t_first, t_last, total, Eigen::MatrixXd(), rhs);
    } else {
      const auto fit = std::get_if<HarmonicFit>(&acc.reduction());
      const int size = fit->basis_size();
      const int harmonic_rows = 2 * order + 1;
      const auto sum = [&](int m) {
        return m >= 0 ? e0[static_cast<std::size_t>(m)] : std::conj(e0[static_cast<std::size_t>(-m)]);
      };
      const auto harmonic = [](int j) { return (j + 1) / 2; };
      const auto is_sine = [](int j) { return j > 0 && j % 2 == 0; };
      Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(size, size);
      Eigen::MatrixXd rhs(size, columns);
      for (int a = 0; a < harmonic_rows; ++a) {
        for (int b = 0; b < harmonic_rows; ++b) {
          const int ka = harmonic(a), kb = harmonic(b);
          const Complex diff = sum(ka - kb), plus = sum(ka + kb);
          if (!is_sine(a) && !is_sine(b))
            normal(a, b) = 0.5 * (diff + plus).real();
          else if (is_sine(a) && is_sine(b))
            normal(a, b) = 0.5 * (diff - plus).real();
          else if (is_sine(a))
            normal(a, b) = 0.5 * (plus + diff).imag();
          else
            normal(a, b) = 0.5 * (plus - diff).imag();
        }
        const Complex* qa = &q[static_cast<std::size_t>(harmonic(a) * columns)];
        for (int c = 0; c < columns; ++c) rhs(a, c) = is_sine(a) ? qa[c].imag() : qa[c].real();
      }
      if (fit->fits_drift()) {
        const int t = harmonic_rows;
        for (int a = 0; a < harmonic_rows; ++a) {
          const Complex w = e1[static_cast<std::size_t>(harmonic(a))];
          normal(a, t) = normal(t, a) = is_sine(a) ? w.imag() : w.real();
        }
        normal(t, t) = tt;
        for (int c = 0; c < columns; ++c) rhs(t, c) = tsum[static_cast<std::size_t>(c)];
      }
      acc.add_sums(t_first, t_last, total, normal, rhs);
    }
    route.fourier = true;
    route.operator_gain = acc.white_noise_gain();
    return true;
  }
  return false;
}

}  // namespace gyrocal
