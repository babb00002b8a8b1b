#include "robust_statistics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace gyrocal::reduce_detail {

/// The median of v (the upper one for an even count: the value std::nth_element puts at v.size() / 2);
/// reorders v. Exact, and about twice as fast as nth_element alone on a block's ~2000 values (the outlier
/// rule's medians were a tenth of a calibration's time, docs/performance.md): the median is bracketed between
/// two values of a sorted sample of 64, one pass counts the values below the bracket and copies those within
/// it, and the search goes on among these (a quarter of them, or fewer) until few are left; a bracket that
/// misses the median (sampling bad luck, or NaN among the values) falls back to nth_element on what is left.
double median(std::vector<double>& v) {
  constexpr std::size_t kSample = 64;
  constexpr std::size_t kReach = 8;  // sample ranks each side of the median's: ~2.8 of its sampling std (4)
  thread_local std::vector<double> scratch;
  std::size_t n = v.size(), k = n / 2;
  double* a = v.data();
  if (n >= 4 * kSample) scratch.resize(2 * n);
  for (int depth = 0; depth < 8 && n >= 4 * kSample; ++depth) {
    std::array<double, kSample> sample;
    const std::size_t stride = n / kSample;
    for (std::size_t i = 0; i < kSample; ++i) sample[i] = a[i * stride + stride / 2];
    std::sort(sample.begin(), sample.end());
    const std::size_t at = (2 * k + 1) * kSample / (2 * n);  // the median's rank in the sample
    const double lo = at >= kReach ? sample[at - kReach] : -std::numeric_limits<double>::infinity();
    const double hi = at + kReach < kSample ? sample[at + kReach] : std::numeric_limits<double>::infinity();
    // Within the bracket go to the scratch's first half, branch-free; the search continues in its second
    // half, so v keeps every value (reordered only by the final nth_element, if that runs on v).
    double* const within = scratch.data();
    std::size_t below = 0, count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = a[i];
      below += x < lo ? 1 : 0;
      within[count] = x;
      count += (x >= lo && x <= hi) ? 1 : 0;
    }
    if (below > k || k >= below + count) break;
    a = scratch.data() + scratch.size() / 2;
    std::copy(within, within + count, a);
    n = count;
    k -= below;
  }
  std::nth_element(a, a + k, a + n);
  return a[k];
}

/// True when no value of x can lie more than `factor` robust spreads from the values' median, whatever the
/// median and the MAD turn out to be: factor * max(kMadToSigma * MAD, floor_lo) bounds the distance from
/// below, with MAD the median of |x - median| (both the upper medians `median` takes) and floor_lo at most
/// the rule's floor. A sufficient condition found from a histogram in two passes, instead of two selections
/// (docs/calibration.md, "Spikes": the rule's outcome is the same; false only means "not shown").
///
/// The values go into kBins bins of width w = (max - min) / kBins by a rounded index, which is monotone in
/// the value and at most one bin off the exact one. (1) The median lies in the bin where the counts pass n/2,
/// so within one bin more on each side: every |x - median| <= D, D from the extremes to that bracket. (2) MAD
/// < h would put n/2 + 1 values within an open interval of length 2h, which with 2h = L w meets at most L + 1
/// exact bins, L + 3 rounded ones: if every run of L + 3 bins holds at most n/2 values, MAD >= L w / 2. The
/// smallest L that makes factor * kMadToSigma * L w / 2 >= D is tested. A relative margin of 1e-9 covers the
/// rounding of these bounds (1e-15 of the range).
bool none_beyond(const std::vector<double>& x, double factor, double floor_lo) {
  constexpr int kBins = 64;
  const std::size_t n = x.size();
  if (n < 2) return false;
  double lo = x[0], hi = x[0];
  for (double v : x) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  const double range = hi - lo;
  if (!std::isfinite(range)) return false;
  constexpr double kMargin = 1.0 - 1e-9;
  if (range <= factor * floor_lo * kMargin) return true;  // every |x - median| <= range
  const double per_bin = kBins / range;
  std::array<std::uint32_t, kBins> count{};
  for (double v : x) {
    if (!(v >= lo && v <= hi)) return false;  // NaN
    ++count[static_cast<std::size_t>(std::min(static_cast<int>((v - lo) * per_bin), kBins - 1))];
  }
  const std::size_t half = n / 2;
  int median_bin = 0;
  for (std::size_t below = 0; median_bin < kBins - 1; ++median_bin) {
    below += count[static_cast<std::size_t>(median_bin)];
    if (below > half) break;
  }
  const double w = range / kBins;
  const double deviation = std::max(hi - (lo + (median_bin - 1) * w), lo + (median_bin + 2) * w - lo);
  const double per_l = factor * kMadToSigma * w / 2.0 * kMargin;
  if (deviation <= factor * floor_lo * kMargin) return true;
  const double l = std::ceil(deviation / per_l);
  if (!(l + 3.0 <= kBins)) return false;
  const int run = static_cast<int>(l) + 3;
  std::size_t in_run = 0;
  for (int j = 0; j < kBins; ++j) {
    in_run += count[static_cast<std::size_t>(j)];
    if (j >= run) in_run -= count[static_cast<std::size_t>(j - run)];
    if (in_run > half) return false;
  }
  return l * per_l >= deviation;
}

}  // namespace gyrocal::reduce_detail
