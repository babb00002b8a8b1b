#include "gyrocal/reduce/measured_rate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace gyrocal {

namespace {

/// The four uniform cubic B-splines that are non-zero on an interval, at t in [0, 1] of it, and their first
/// and second derivatives with respect to t.
void basis(double t, double b[4], double d1[4], double d2[4]) {
  const double s = 1.0 - t, t2 = t * t, t3 = t2 * t;
  b[0] = s * s * s / 6.0;
  b[1] = (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0;
  b[2] = (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0;
  b[3] = t3 / 6.0;
  d1[0] = -0.5 * s * s;
  d1[1] = 0.5 * (3.0 * t2 - 4.0 * t);
  d1[2] = 0.5 * (-3.0 * t2 + 2.0 * t + 1.0);
  d1[3] = 0.5 * t2;
  d2[0] = s;
  d2[1] = 3.0 * t - 2.0;
  d2[2] = -3.0 * t + 1.0;
  d2[3] = t;
}

/// The interval of u (in knot intervals from the first knot) among a spline's `knots` coefficients, clamped
/// to the ones it has, and u's place in it.
std::size_t interval_of(double u, std::size_t coefficients, double& t) {
  const double last = static_cast<double>(coefficients - 4);
  const double j = std::clamp(std::floor(u), 0.0, last);
  t = u - j;
  return static_cast<std::size_t>(j);
}

/// Cholesky factor of a symmetric band matrix of half-bandwidth 3 (band[4 k + m] = M(k, k + m)), in place as
/// L(k + m, k) = band[4 k + m]; false if it is not positive definite.
bool factor(std::vector<double>& band, std::size_t n) {
  // Work on the lower form: L(i, i - m) at low[4 i + m].
  std::vector<double> low(4 * n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t m = 0; m < 4 && m <= i; ++m) low[4 * i + m] = band[4 * (i - m) + m];
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j0 = i >= 3 ? i - 3 : 0;
    for (std::size_t j = j0; j <= i; ++j) {
      double s = low[4 * i + (i - j)];
      for (std::size_t k = j0; k < j; ++k) s -= low[4 * i + (i - k)] * low[4 * j + (j - k)];
      if (j == i) {
        if (!(s > 0.0)) return false;
        low[4 * i] = std::sqrt(s);
      } else {
        low[4 * i + (i - j)] = s / low[4 * j];
      }
    }
  }
  band = std::move(low);
  return true;
}

/// Solves L L^T x = b with the factor of `factor` (low[4 i + m] = L(i, i - m)).
std::vector<double> solve(const std::vector<double>& low, std::vector<double> b) {
  const std::size_t n = b.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t m = 1; m < 4 && m <= i; ++m) b[i] -= low[4 * i + m] * b[i - m];
    b[i] /= low[4 * i];
  }
  for (std::size_t i = n; i-- > 0;) {
    for (std::size_t m = 1; m < 4 && i + m < n; ++m) b[i] -= low[4 * (i + m) + m] * b[i + m];
    b[i] /= low[4 * i];
  }
  return b;
}

/// v^T (L L^T)^-1 v = |L^-1 v|^2 for a v that is zero outside [first, first + 4), by forward substitution
/// alone. Beyond v's entries L^-1 v decays geometrically through the subnormal range, where each operation
/// costs ~100 times a normal one (the full two-way solve of a dwell's 16 000 knots took ~10 ms there, 4 % of
/// calibrate's CPU): an entry below 1e-100 of the largest is taken as 0 (its square is below 1e-200 of the
/// sum), and once three in a row are 0 past v's entries the homogeneous recurrence gives only zeros, so the
/// substitution stops there: the sum is the full one's to rounding.
double inverse_quadratic_form(const std::vector<double>& low, const std::vector<double>& v,
                              std::size_t first) {
  const std::size_t n = v.size();
  double y[4] = {0.0, 0.0, 0.0, 0.0};  // y[i % 4]: the last entries of L^-1 v
  double sum = 0.0, largest = 0.0;
  std::size_t zeros = 0;
  for (std::size_t i = first; i < n; ++i) {
    double yi = v[i];
    for (std::size_t m = 1; m < 4 && m <= i - first; ++m) yi -= low[4 * i + m] * y[(i - m) % 4];
    yi /= low[4 * i];
    largest = std::max(largest, std::abs(yi));
    if (std::abs(yi) < 1e-100 * largest) yi = 0.0;
    y[i % 4] = yi;
    sum += yi * yi;
    zeros = yi == 0.0 ? zeros + 1 : 0;
    if (zeros >= 3 && i >= first + 6) break;  // three zeros past v's entries
  }
  return sum;
}

}  // namespace

MeasuredState MeasuredMotion::at(std::size_t phase, double x_s) const {
  MeasuredState s;
  s.angle_rad = origin_rad + reference_rate_rad_s * (x_s - origin_s);
  s.rate_rad_s = reference_rate_rad_s;
  if (phase >= phases.size()) return s;
  const MeasuredPhase& p = phases[phase];
  const double u = (x_s - p.first_knot_s) / knot_interval_s;
  if (p.coefficients.size() < 4) {
    s.angle_rad += p.line_at_rad + p.line_rate_rad_s * (x_s - p.first_knot_s);
    s.rate_rad_s += p.line_rate_rad_s;
    return s;
  }
  double t = 0.0;
  const std::size_t j = interval_of(u, p.coefficients.size(), t);
  double b[4], d1[4], d2[4];
  basis(t, b, d1, d2);
  for (std::size_t m = 0; m < 4; ++m) {
    const double c = p.coefficients[j + m];
    s.angle_rad += c * b[m];
    s.rate_rad_s += c * d1[m] / knot_interval_s;
    s.accel_rad_s2 += c * d2[m] / (knot_interval_s * knot_interval_s);
  }
  return s;
}

MeasuredMotionFit::MeasuredMotionFit(double grid_interval_s, double origin_s, double origin_rad,
                                     double reference_rate_rad_s, double knot_interval_s, double span_s) {
  out_.grid_interval_s = grid_interval_s;
  const double h = std::max(knot_interval_s, 8.0 * grid_interval_s);
  out_.knot_interval_s = span_s > h ? span_s / std::round(span_s / h) : h;
  inverse_knot_interval_ = 1.0 / out_.knot_interval_s;
  out_.origin_s = origin_s;
  out_.origin_rad = origin_rad;
  out_.reference_rate_rad_s = reference_rate_rad_s;
  span_s_ = span_s;
}

void MeasuredMotionFit::begin_phase(double x_s) {
  phases_.emplace_back();
  Phase& p = phases_.back();
  p.first_knot = x_s;
  // The first phase spans the planned span (the reducer measures no further): its knots are known, and held
  // in arrays of their size, not in arrays doubled as they grow (twice the memory, three times while one is
  // copied to the next; docs/performance.md).
  if (phases_.size() == 1 && span_s_ > 0.0 && std::isfinite(span_s_ * inverse_knot_interval_)) {
    const auto knots = static_cast<std::size_t>(std::ceil(span_s_ * inverse_knot_interval_)) + 4;
    p.rhs.reserve(knots);
    p.band.reserve(4 * knots);
  }
}

namespace {

/// The uniform cubic B-splines of `basis` as polynomials in t: b[a](t) = sum_k kSplinePoly[a][k] t^k / 6.
constexpr double kSplinePoly[4][4] = {{1, -3, 3, -1}, {4, 0, -6, 3}, {1, 3, 3, -3}, {0, 0, 0, 1}};

/// The products b[a] b[a + m] as polynomials of degree 6: kSplineProducts[a][m][k] / 36.
struct SplineProducts {
  double c[4][4][7] = {};
  constexpr SplineProducts() {
    for (int a = 0; a < 4; ++a)
      for (int m = 0; a + m < 4; ++m)
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j) c[a][m][i + j] += kSplinePoly[a][i] * kSplinePoly[a + m][j];
  }
};
constexpr SplineProducts kSplineProducts;

}  // namespace

void MeasuredMotionFit::fold(Phase& p) {
  if (p.t_moment[0] == 0.0) return;
  const std::size_t j = p.interval;
  if (p.rhs.size() < j + 4) {
    p.rhs.resize(j + 4, 0.0);
    p.band.resize(4 * (j + 4), 0.0);
  }
  for (std::size_t a = 0; a < 4; ++a) {
    double r = 0.0;
    for (std::size_t k = 0; k < 4; ++k) r += kSplinePoly[a][k] * p.ty_moment[k];
    p.rhs[j + a] += r / 6.0;
    for (std::size_t m = 0; a + m < 4; ++m) {
      double v = 0.0;
      for (std::size_t k = 0; k < 7; ++k) v += kSplineProducts.c[a][m][k] * p.t_moment[k];
      p.band[4 * (j + a) + m] += v / 36.0;
    }
  }
  for (double& v : p.t_moment) v = 0.0;
  for (double& v : p.ty_moment) v = 0.0;
}

MeasuredMotion MeasuredMotionFit::finish() {
  for (Phase& p : phases_) fold(p);
  MeasuredMotion out = out_;
  const double h = out.knot_interval_s;
  double rss_line = 0.0, rss_spline = 0.0, parameters = 0.0, dof = 0.0;
  std::size_t longest = 0, longest_n = 0;
  std::vector<std::vector<double>> factors(phases_.size());
  for (std::size_t pi = 0; pi < phases_.size(); ++pi) {
    const Phase& p = phases_[pi];
    MeasuredPhase mp;
    mp.first_knot_s = p.first_knot;
    const double sxx = p.sxx - p.sx * p.sx / std::max(p.n, 1.0);
    const double sxy = p.sxy - p.sx * p.sy / std::max(p.n, 1.0);
    const double syy = p.syy - p.sy * p.sy / std::max(p.n, 1.0);
    mp.line_rate_rad_s = sxx > 0.0 ? sxy / sxx : 0.0;
    mp.line_at_rad = p.n > 0 ? (p.sy - mp.line_rate_rad_s * p.sx) / p.n : 0.0;
    const double line_rss = std::max(syy - mp.line_rate_rad_s * sxy, 0.0);
    rss_line += line_rss;
    const std::size_t k = p.rhs.size();
    bool spline = p.n >= 16 && k >= 4;
    if (spline) {
      // A light penalty on the coefficients' third differences (zero on quadratics, so no bias on a steady
      // or uniformly accelerating arm) keeps a sparsely sampled end interval well posed.
      std::vector<double> band = p.band;
      const double lambda = 1e-6 * h / out.grid_interval_s;
      const double d[4] = {1.0, -3.0, 3.0, -1.0};
      // The first and last intervals hold the only data of their outer coefficient (at most 1/6 of it): they
      // are held to the quadratic of their neighbour's (a strong penalty on the end windows), so that the
      // ends are not extrapolations of one interval's readings.
      const double lambda_end = 1e-6 * h / out.grid_interval_s;
      for (std::size_t w = 0; w + 3 < k; ++w) {
        const double l = w == 0 || w + 4 == k ? lambda_end : lambda;
        for (std::size_t a = 0; a < 4; ++a)
          for (std::size_t m = 0; a + m < 4; ++m) band[4 * (w + a) + m] += l * d[a] * d[a + m];
      }
      spline = factor(band, k);
      if (spline) {
        mp.coefficients = solve(band, p.rhs);
        factors[pi] = std::move(band);
        // Residual sum of squares about the spline: syy - 2 c.r + c M c (M the data's normal matrix).
        double cmc = 0.0, cr = 0.0;
        for (std::size_t i = 0; i < k; ++i) {
          cr += mp.coefficients[i] * p.rhs[i];
          cmc += mp.coefficients[i] * mp.coefficients[i] * p.band[4 * i];
          for (std::size_t m = 1; m < 4 && i + m < k; ++m)
            cmc += 2.0 * mp.coefficients[i] * mp.coefficients[i + m] * p.band[4 * i + m];
        }
        const double spline_rss = std::clamp(p.syy - 2.0 * cr + cmc, 0.0, line_rss);
        rss_spline += spline_rss;
        parameters += static_cast<double>(k);
        dof += static_cast<double>(k) - 2.0;
        if (static_cast<std::size_t>(p.n) > longest_n)
          longest = pi, longest_n = static_cast<std::size_t>(p.n);
        // The largest deviation from the phase's line, 8 points an interval over the sampled span (the
        // basis at those 9 places is the same in every interval: evaluated once).
        const std::size_t intervals = k - 3;
        double qb[9][4], qd1[9][4], qd2[9][4];
        for (int q = 0; q <= 8; ++q) basis(q / 8.0, qb[q], qd1[q], qd2[q]);
        for (std::size_t j = 0; j < intervals; ++j)
          for (int q = 0; q <= 8; ++q) {
            const double* b = qb[q];
            const double* d1 = qd1[q];
            const double* d2 = qd2[q];
            double a = 0.0, r = 0.0, acc = 0.0;
            for (std::size_t m = 0; m < 4; ++m) {
              a += mp.coefficients[j + m] * b[m];
              r += mp.coefficients[j + m] * d1[m] / h;
              acc += mp.coefficients[j + m] * d2[m] / (h * h);
            }
            const double x = (static_cast<double>(j) + q / 8.0) * h;
            out.max_angle_deviation_rad =
                std::max(out.max_angle_deviation_rad, std::abs(a - mp.line_at_rad - mp.line_rate_rad_s * x));
            out.max_rate_deviation_rad_s =
                std::max(out.max_rate_deviation_rad_s, std::abs(r - mp.line_rate_rad_s));
            out.max_accel_rad_s2 = std::max(out.max_accel_rad_s2, std::abs(acc));
          }
      }
    }
    if (!spline) {
      rss_spline += line_rss;
      parameters += 2.0;
    }
    out.phases.push_back(std::move(mp));
  }
  const double n = static_cast<double>(out.samples);
  const double s2 = n > parameters ? rss_spline / (n - parameters) : 0.0;
  out.residual_rad = std::sqrt(s2);
  out.dof = dof;
  // The residual sum about the spline comes from syy - 2 c.r + c M c, whose rounding is ~1e-14 of syy: an
  // arm followed to within that (noise-free readings of a fine encoder, a ripple the spline holds whole)
  // leaves a scatter of 0 or of rounding, which would make the F-test 0 / 0 (a rippled record of 100
  // revolutions at 200 Hz read as unresolved and left on its lines: Kio missed by 0.5 ug/g^2). The scatter is
  // taken as at least that rounding.
  double syy_all = 0.0;
  for (const Phase& p : phases_) syy_all += p.syy;
  const double s2_test = n > 0.0 ? std::max(s2, 1e-14 * syy_all / n) : 0.0;
  out.chi2 = s2_test > 0.0 ? (rss_line - rss_spline) / s2_test : 0.0;
  out.resolved = dof > 0.0 && out.chi2 > dof + 8.0 * std::sqrt(2.0 * dof);
  out.quanta_resolved = out.max_angle_deviation_rad > 0.6 * out.count_bound_rad;
  // The spline's own noise at the middle of the longest phase's middle interval: s^2 b^T (M + P)^-1 b.
  if (longest_n > 0) {
    const std::size_t k = out.phases[longest].coefficients.size();
    const std::size_t j = (k - 3) / 2;
    double b[4], d1[4], d2[4];
    basis(0.5, b, d1, d2);
    std::vector<double> vb(k, 0.0), vd(k, 0.0);
    for (std::size_t m = 0; m < 4; ++m) vb[j + m] = b[m], vd[j + m] = d1[m] / h;
    const double qb = inverse_quadratic_form(factors[longest], vb, j),
                 qd = inverse_quadratic_form(factors[longest], vd, j);
    out.angle_noise_rad = std::sqrt(s2 * qb);
    out.rate_noise_rad_s = std::sqrt(s2 * qd);
  }
  return out;
}

}  // namespace gyrocal
