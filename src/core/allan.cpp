#include "gyrocal/core/allan.hpp"

#include <cmath>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"

namespace gyrocal {

namespace {

// Neumaier's compensated sum: the running total and its rounding error.
struct CompensatedSum {
  double sum = 0.0;
  double compensation = 0.0;

  void add(double x) {
    const double t = sum + x;
    compensation += std::abs(sum) >= std::abs(x) ? (sum - t) + x : (x - t) + sum;
    sum = t;
  }
  double value() const { return sum + compensation; }
};

}  // namespace

std::vector<std::size_t> log_spaced_cluster_sizes(std::size_t sample_count, int points_per_decade) {
  std::vector<std::size_t> sizes;
  if (sample_count < 2 || points_per_decade < 1) return sizes;
  const std::size_t largest = sample_count / 2;
  for (int j = 0;; ++j) {
    const double m = std::round(std::pow(10.0, static_cast<double>(j) / points_per_decade));
    if (m > static_cast<double>(largest)) break;
    const auto size = static_cast<std::size_t>(m);
    if (sizes.empty() || size > sizes.back()) sizes.push_back(size);
  }
  return sizes;
}

AllanDeviation overlapping_allan_deviation(std::span<const double> rate, double sample_rate_hz,
                                           std::span<const std::size_t> cluster_sizes) {
  if (!std::isfinite(sample_rate_hz) || sample_rate_hz <= 0.0) {
    throw Error(fmt::format("Allan deviation: the sample rate must be a finite number > 0 Hz, got {}.",
                            sample_rate_hz));
  }
  const std::size_t n = rate.size();
  if (n < 2) throw Error(fmt::format("Allan deviation: need at least 2 samples, got {}.", n));
  for (std::size_t m : cluster_sizes) {
    if (m < 1 || m > n / 2) {
      throw Error(fmt::format("Allan deviation: cluster size {} is out of range 1 to {} for {} samples.", m,
                              n / 2, n));
    }
  }

  CompensatedSum total;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(rate[i])) throw Error(fmt::format("Allan deviation: sample {} is not finite.", i));
    total.add(rate[i]);
  }
  const double mean = total.value() / static_cast<double>(n);
  // theta_k = sum_{i<k} (y_i - mean), in rate x samples; each stored value is the rounded compensated sum, so
  // its error does not grow with k.
  std::vector<double> theta(n + 1);
  CompensatedSum running;
  theta[0] = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    running.add(rate[i] - mean);
    theta[i + 1] = running.value();
  }

  AllanDeviation result;
  result.cluster_size.reserve(cluster_sizes.size());
  result.tau_s.reserve(cluster_sizes.size());
  result.deviation.reserve(cluster_sizes.size());
  result.relative_uncertainty.reserve(cluster_sizes.size());
  for (std::size_t m : cluster_sizes) {
    const std::size_t terms = n + 1 - 2 * m;  // starts k = 0 .. N - 2m
    double sum_squares = 0.0;
    for (std::size_t k = 0; k < terms; ++k) {
      const double d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
      sum_squares += d * d;
    }
    // With theta in rate x samples, (theta/fs)^2 / tau^2 = theta^2 / m^2.
    const double md = static_cast<double>(m);
    const double variance = sum_squares / (2.0 * md * md * static_cast<double>(terms));
    const double clusters = std::floor(static_cast<double>(n) / md);
    result.cluster_size.push_back(m);
    result.tau_s.push_back(md / sample_rate_hz);
    result.deviation.push_back(std::sqrt(variance));
    result.relative_uncertainty.push_back(1.0 / std::sqrt(2.0 * (clusters - 1.0)));
  }
  return result;
}

AllanDeviation overlapping_allan_deviation(std::span<const double> rate, double sample_rate_hz) {
  const std::vector<std::size_t> sizes = log_spaced_cluster_sizes(rate.size());
  return overlapping_allan_deviation(rate, sample_rate_hz, sizes);
}

}  // namespace gyrocal
