#include "gyrocal/analysis/repeatability.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "gyrocal/core/noise_terms.hpp"
#include "gyrocal/core/special_functions.hpp"

// The statistics of docs/history.md, "The statistics", each as repeatability.hpp defines it. Sums run in the
// runs' order, centred on the mean first (two passes), so that a coefficient of 1e6 with a scatter of 1e-3
// keeps its digits.

namespace gyrocal {
namespace {

/// d2 for subgroups of two, the ratio of the expected moving range of two normal values to their sigma
/// (2/sqrt(pi) = 1.1284; NIST/SEMATECH e-Handbook 6.3.2.2 uses 1.128).
constexpr double kD2 = 1.128;

void check_options(const RepeatabilityOptions& o) {
  if (!(o.interval > 0.0 && o.interval < 1.0))
    throw std::invalid_argument(
        fmt::format("repeatability: the interval's probability must be in (0, 1), got {}.", o.interval));
  if (!(o.shewhart_k > 0.0) || !std::isfinite(o.shewhart_k))
    throw std::invalid_argument(
        fmt::format("repeatability: the Shewhart limits' k must be finite and > 0, got {}.", o.shewhart_k));
  if (!(o.ewma_lambda > 0.0 && o.ewma_lambda <= 1.0))
    throw std::invalid_argument(
        fmt::format("repeatability: the EWMA's lambda must be in (0, 1], got {}.", o.ewma_lambda));
  if (!(o.ewma_k > 0.0) || !std::isfinite(o.ewma_k))
    throw std::invalid_argument(
        fmt::format("repeatability: the EWMA limits' k must be finite and > 0, got {}.", o.ewma_k));
}

void check_values(std::span<const RunValue> values) {
  if (values.empty()) throw std::invalid_argument("repeatability: no runs.");
  for (std::size_t i = 0; i < values.size(); ++i) {
    const RunValue& v = values[i];
    if (!std::isfinite(v.value))
      throw std::invalid_argument(
          fmt::format("repeatability: run {} has a value that is not finite.", v.run_id));
    if (!(v.std > 0.0) || !std::isfinite(v.std))
      throw std::invalid_argument(
          fmt::format("repeatability: run {} has a std of {}; it must be finite and > 0.", v.run_id, v.std));
    if (!std::isfinite(v.day))
      throw std::invalid_argument(
          fmt::format("repeatability: run {} has a date that is not finite.", v.run_id));
    if (i > 0) {
      const RunValue& p = values[i - 1];
      if (v.day < p.day || (v.day == p.day && v.run_id < p.run_id))
        throw std::invalid_argument(fmt::format(
            "repeatability: run {} comes after run {} but is earlier; give the runs in date order.", v.run_id,
            p.run_id));
    }
  }
}

}  // namespace

Repeatability repeatability(std::span<const RunValue> values, const RepeatabilityOptions& options) {
  check_options(options);
  check_values(values);
  Repeatability r;
  const std::size_t n = values.size();
  const double nd = static_cast<double>(n);
  r.runs = n;

  // Weighted mean and the chi-square of the values about it. Sums of the differences from the first value,
  // so that equal values give their value exactly (and no rounding flags or trends).
  const double x0 = values.front().value;
  double sum_w = 0.0, sum_wdx = 0.0, sum_var = 0.0, sum_dx = 0.0;
  for (const RunValue& v : values) {
    const double w = 1.0 / (v.std * v.std);
    sum_w += w;
    sum_wdx += w * (v.value - x0);
    sum_var += v.std * v.std;
    sum_dx += v.value - x0;
  }
  r.mean = x0 + sum_wdx / sum_w;
  r.mean_std = 1.0 / std::sqrt(sum_w);
  r.mean_stated_std = std::sqrt(sum_var / nd);
  const double xbar = x0 + sum_dx / nd;  // the unweighted mean: the sample std's and the charts' centre
  if (n == 1) return r;

  double chi2 = 0.0, sum_dx2 = 0.0;
  for (const RunValue& v : values) {
    const double z = (v.value - r.mean) / v.std;
    chi2 += z * z;
    sum_dx2 += (v.value - xbar) * (v.value - xbar);
  }
  const double dof = nd - 1.0;
  const double birge = std::sqrt(chi2 / dof);
  if (birge > 1.0) r.mean_std *= birge;

  // Run-to-run std and its chi-square interval: (n-1) s^2 / sigma^2 ~ chi2(n-1).
  const double s = std::sqrt(sum_dx2 / dof);
  r.run_to_run_std = s;
  const DeviationBounds bounds = deviation_confidence_bounds(s, dof, options.interval);
  r.run_to_run_std_low = bounds.low;
  r.run_to_run_std_high = bounds.high;
  r.std_ratio = s / r.mean_stated_std;
  // F(n-1, infinity): (n-1) X = chi2 ~ chi2(n-1) when the stated sigma explain the scatter.
  // (A chi2 that overflowed is beyond any doubt.)
  r.f_test_p = std::isinf(chi2) ? 0.0 : regularized_gamma_q(0.5 * dof, 0.5 * chi2);

  // The trend: ordinary least squares of value against day, with n >= 3 and two different dates.
  const auto [first, last] = std::minmax_element(
      values.begin(), values.end(), [](const RunValue& a, const RunValue& b) { return a.day < b.day; });
  if (n >= 3 && last->day > first->day) {
    double sum_dt = 0.0;
    for (const RunValue& v : values) sum_dt += v.day - values.front().day;
    const double tbar = values.front().day + sum_dt / nd;
    double stt = 0.0, stx = 0.0;
    for (const RunValue& v : values) {
      stt += (v.day - tbar) * (v.day - tbar);
      stx += (v.day - tbar) * (v.value - xbar);
    }
    if (stt > 0.0) {
      const double slope = stx / stt;
      double rss = 0.0;
      for (const RunValue& v : values) {
        const double e = v.value - xbar - slope * (v.day - tbar);
        rss += e * e;
      }
      const double slope_std = std::sqrt(rss / (nd - 2.0) / stt);
      r.trend_per_day = slope;
      r.trend_std = slope_std;
      // A perfect line: certain when it slopes, no evidence when it is flat.
      if (slope_std > 0.0) {
        r.trend_p = student_t_two_sided_p(slope / slope_std, nd - 2.0);
      } else {
        r.trend_p = slope != 0.0 ? 0.0 : 1.0;
      }
    }
  }

  // The individuals chart (NIST/SEMATECH e-Handbook 6.3.2.2): sigma from the average moving range.
  double sum_mr = 0.0;
  for (std::size_t i = 1; i < n; ++i) sum_mr += std::abs(values[i].value - values[i - 1].value);
  const double sigma = sum_mr / (nd - 1.0) / kD2;
  r.chart_sigma = sigma;
  const double low = xbar - options.shewhart_k * sigma, high = xbar + options.shewhart_k * sigma;
  r.limits = std::array<double, 2>{low, high};
  // Equal values (sigma 0) leave nothing outside.
  for (const RunValue& v : values)
    if (sigma > 0.0 && (v.value < low || v.value > high)) r.flagged.push_back(v.run_id);

  // The EWMA (e-Handbook 6.3.2.4), started at the centre.
  const double lambda = options.ewma_lambda;
  double z = xbar, decay2 = 1.0;  // decay2 = (1 - lambda)^(2i)
  r.ewma.reserve(n);
  r.ewma_limits.reserve(n);
  for (const RunValue& v : values) {
    z = lambda * v.value + (1.0 - lambda) * z;
    decay2 *= (1.0 - lambda) * (1.0 - lambda);
    const double half = options.ewma_k * sigma * std::sqrt(lambda / (2.0 - lambda) * (1.0 - decay2));
    r.ewma.push_back(z);
    r.ewma_limits.push_back({xbar - half, xbar + half});
    if (sigma > 0.0 && (z < xbar - half || z > xbar + half)) r.ewma_flagged.push_back(v.run_id);
  }
  return r;
}

}  // namespace gyrocal
