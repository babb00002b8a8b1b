#include "gyrocal/core/special_functions.hpp"

#include <cmath>
#include <limits>

// The regularised incomplete gamma and beta functions by their series and continued fractions (the modified
// Lentz method; Numerical Recipes, sections 6.2 and 6.4). Q is taken from its continued fraction directly
// where it is small, so that a p-value of 1e-12 (identify/misfit) keeps its digits instead of being 1 - P.

namespace gyrocal {
namespace {

/// Continued fraction of the regularised incomplete beta function (modified Lentz).
double beta_continued_fraction(double a, double b, double x) {
  constexpr double kTiny = 1e-300;
  const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
  double c = 1.0, d = 1.0 - qab * x / qap;
  if (std::abs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= 10000; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15) break;
  }
  return h;
}

/// The series of P(a, x) without its front factor x^a e^-x / Gamma(a): converges fast below x = a + 1.
double gamma_series(double a, double x) {
  double term = 1.0 / a;
  double sum = term;
  for (int n = 1; n < 10000; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * 1e-17) break;
  }
  return sum;
}

/// The continued fraction of Q(a, x) without its front factor (modified Lentz): converges fast above
/// x = a + 1.
double gamma_continued_fraction(double a, double x) {
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  return h;
}

/// x^a e^-x / Gamma(a).
double gamma_front(double a, double x) {
  return std::exp(a * std::log(x) - x - std::lgamma(a));
}

}  // namespace

double regularized_beta(double a, double b, double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  const double front =
      std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x));
  if (x < (a + 1.0) / (a + b + 2.0)) return front * beta_continued_fraction(a, b, x) / a;
  return 1.0 - front * beta_continued_fraction(b, a, 1.0 - x) / b;
}

double regularized_gamma_p(double a, double x) {
  if (x <= 0.0) return 0.0;
  if (x < a + 1.0) return gamma_front(a, x) * gamma_series(a, x);
  return 1.0 - gamma_front(a, x) * gamma_continued_fraction(a, x);
}

double regularized_gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  if (x < a + 1.0) return 1.0 - gamma_front(a, x) * gamma_series(a, x);
  return gamma_front(a, x) * gamma_continued_fraction(a, x);
}

double student_t_two_sided_p(double t, double dof) {
  if (std::isnan(t) || !(dof > 0.0) || !std::isfinite(dof)) return std::numeric_limits<double>::quiet_NaN();
  if (std::isinf(t)) return 0.0;
  return regularized_beta(0.5 * dof, 0.5, dof / (dof + t * t));
}

}  // namespace gyrocal
