#pragma once
// The outlier rule's robust statistics (docs/calibration.md, "Spikes"): an exact median faster than
// nth_element alone, and a histogram's proof that no value lies beyond the rule's threshold. Internal to
// src/reduce.
#include <vector>

namespace gyrocal::reduce_detail {

/// The median of v (the upper one for an even count: the value std::nth_element puts at v.size() / 2);
/// reorders v. Exact (robust_statistics.cpp says how it is found).
double median(std::vector<double>& v);

/// 1 / Phi^-1(3/4): the median absolute deviation of normal noise times this is its standard deviation.
inline constexpr double kMadToSigma = 1.482602218505602;

/// True when no value of x can lie more than `factor` robust spreads from the values' median, whatever the
/// median and the MAD turn out to be (factor * max(kMadToSigma * MAD, floor_lo) bounds the distance from
/// below); false only means "not shown" (robust_statistics.cpp).
bool none_beyond(const std::vector<double>& x, double factor, double floor_lo);

}  // namespace gyrocal::reduce_detail
