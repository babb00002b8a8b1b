#pragma once
// The overlapping Allan deviation of a rate series (IEEE Std 952-1997, annex C; docs/noise.md).
//
// For rate samples y_0 .. y_{N-1} at rate fs, cluster size m and tau = m / fs, with the angle
// theta_k = (1/fs) sum_{i<k} y_i:
//   sigma^2(tau) = 1 / (2 tau^2 (N + 1 - 2m)) * sum_{k=0}^{N-2m} (theta_{k+2m} - 2 theta_{k+m} + theta_k)^2,
// i.e. half the mean square difference of the averages of two adjacent clusters, over every start k. The
// deviation is in the rate's unit. The mean is removed and the angles are summed with compensation first, so
// a large constant rate costs no precision.
#include <cstddef>
#include <span>
#include <vector>

namespace gyrocal {

/// The Allan deviation at a list of cluster sizes (all vectors of the same length, in the order asked).
struct AllanDeviation {
  std::vector<std::size_t> cluster_size;  ///< m, samples per cluster
  std::vector<double> tau_s;              ///< cluster time m / fs, s
  std::vector<double> deviation;          ///< sigma(tau), unit of the rate series
  /// Approximate 1-sigma relative uncertainty of deviation: 1 / sqrt(2 (floor(N/m) - 1)), the value for
  /// non-overlapping clusters (IEEE 952, annex C). The overlapping estimator does at least as well, so this
  /// is conservative (by up to a factor ~1.6 for white noise at large m).
  std::vector<double> relative_uncertainty;
};

/// About points_per_decade (>= 1) distinct cluster sizes from 1 to floor(sample_count / 2), spaced
/// logarithmically (round(10^(j / points_per_decade)), j = 0, 1, ...), increasing; none for fewer than 2
/// samples.
std::vector<std::size_t> log_spaced_cluster_sizes(std::size_t sample_count, int points_per_decade = 10);

/// Overlapping Allan deviation of rate (any unit) sampled at sample_rate_hz (> 0) for each cluster size m of
/// cluster_sizes (each 1 <= m <= N / 2). Throws Error on a bad sample rate, a series shorter than 2 samples
/// or with a non-finite sample, or a cluster size out of range.
AllanDeviation overlapping_allan_deviation(std::span<const double> rate, double sample_rate_hz,
                                           std::span<const std::size_t> cluster_sizes);

/// The same at log_spaced_cluster_sizes(rate.size()).
AllanDeviation overlapping_allan_deviation(std::span<const double> rate, double sample_rate_hz);

}  // namespace gyrocal
