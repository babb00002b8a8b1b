#include "gyrocal/record/increments.hpp"

#include <cmath>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"

namespace gyrocal {

IntervalRule interval_rule(int nodes) {
  if (nodes < 1 || nodes > kMaxIntervalNodes)
    throw Error(fmt::format("An interval's mean is taken with 1 to {} Gauss-Legendre nodes, not {}.",
                            kMaxIntervalNodes, nodes));
  constexpr double kPi = 3.14159265358979323846;
  const auto n = static_cast<std::size_t>(nodes);
  IntervalRule rule;
  rule.back.resize(n);
  rule.weight.resize(n);
  // The roots x of P_n on [-1, 1] from Tricomi's first guess, by Newton's iteration on the three-term
  // recurrence; weight 2 / ((1 - x^2) P_n'(x)^2), halved for a mean.
  for (std::size_t i = 0; i < (n + 1) / 2; ++i) {
    double x = std::cos(kPi * (static_cast<double>(i) + 0.75) / (static_cast<double>(n) + 0.5));
    double derivative = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0, p1 = x;
      for (std::size_t k = 2; k <= n; ++k) {
        const double kk = static_cast<double>(k);
        const double p2 = ((2.0 * kk - 1.0) * x * p1 - (kk - 1.0) * p0) / kk;
        p0 = p1;
        p1 = p2;
      }
      derivative = static_cast<double>(n) * (x * p1 - p0) / (x * x - 1.0);
      const double step = p1 / derivative;
      x -= step;
      if (std::abs(step) <= 1e-17) break;
    }
    const double w = 1.0 / ((1.0 - x * x) * derivative * derivative);  // half of Gauss's weight
    // x in [-1, 1] is s = t - dt (1 - x) / 2: back = (1 - x) / 2 and its mirror (1 + x) / 2.
    rule.back[i] = 0.5 * (1.0 - x);
    rule.back[n - 1 - i] = 0.5 * (1.0 + x);
    rule.weight[i] = rule.weight[n - 1 - i] = w;
  }
  if (n % 2 == 1) rule.back[n / 2] = 0.5;  // the middle root is 0 exactly
  return rule;
}

int interval_nodes(double max_phase_rad) {
  const double a = 0.5 * std::abs(max_phase_rad);
  if (!(a > 0.0)) return 1;
  // 2^(2n) (n!)^4 / ((2n + 1) ((2n)!)^3) a^(2n), built term by term from n = 1.
  double factor = 4.0 / (3.0 * 8.0);  // n = 1: 4 x 1 / (3 x 2^3)
  for (int n = 1; n <= kMaxIntervalNodes; ++n) {
    if (factor * std::pow(a, 2 * n) <= 1e-13) return n;
    const double m = static_cast<double>(n + 1);
    // n -> n + 1: x 4 (n+1)^4 (2n+1) / ((2n+3) ((2n+1)(2n+2))^3)
    factor *=
        4.0 * m * m * m * m * (2.0 * m - 1.0) / ((2.0 * m + 1.0) * std::pow((2.0 * m - 1.0) * (2.0 * m), 3));
  }
  return kMaxIntervalNodes;
}

std::complex<double> interval_mean_factor(double f_rad_s, double dt_s) {
  const double x = 0.5 * f_rad_s * dt_s;
  const double x2 = x * x;
  // sin(x) / x, by its series where the quotient would lose digits.
  const double sinc = std::abs(x) < 1e-4 ? 1.0 - x2 / 6.0 + x2 * x2 / 120.0 : std::sin(x) / x;
  return {sinc * std::cos(x), -sinc * std::sin(x)};
}

}  // namespace gyrocal
