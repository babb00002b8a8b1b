// The repeatability of one quantity over a unit's runs (analysis/repeatability.hpp, docs/history.md "The
// statistics"): the distribution functions against printed tables, every statistic against a hand
// computation, and the statistics' behaviour against the test's own generator of runs (a value per run with
// its stated sigma, an optional turn-on scatter tau redrawn per run, an optional trend): the interval's
// coverage, the F-test's power and its p-values' uniformity, the trend's test, and the control charts.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "gyrocal/analysis/repeatability.hpp"
#include "gyrocal/core/noise_terms.hpp"
#include "gyrocal/core/random.hpp"
#include "gyrocal/core/special_functions.hpp"

namespace gyrocal {
namespace {

bool sanitized() {
  return std::getenv("GYROCAL_SANITIZED") != nullptr;
}

/// Trials of a statistical test: fewer under the sanitizers (their bands below widen with 1/sqrt(trials)).
int trials(int release, int sanitized_count) {
  return sanitized() ? sanitized_count : release;
}

/// The test's own generator of a unit's history: run i (id i + 1) on day i * spacing_days holds
/// truth + trend_per_day * day + tau * N(0,1) (the turn-on scatter, redrawn per run) + sigma_i * N(0,1) (the
/// run's own noise), and states sigma_i. With spread > 0, sigma_i = sigma * (1 + spread * U(-1, 1)).
struct Generator {
  double truth = 1.0;
  double sigma = 0.1;
  double tau = 0.0;
  double trend_per_day = 0.0;
  double spacing_days = 7.0;
  double spread = 0.0;

  std::vector<RunValue> history(std::size_t n, std::uint64_t seed) const {
    RandomSource rng(seed, 30);
    std::vector<RunValue> out;
    for (std::size_t i = 0; i < n; ++i) {
      RunValue v;
      v.run_id = static_cast<std::int64_t>(i + 1);
      v.day = 20000.0 + static_cast<double>(i) * spacing_days;
      v.std = sigma * (1.0 + spread * (2.0 * rng.uniform() - 1.0));
      v.value = truth + trend_per_day * (v.day - 20000.0) + tau * rng.normal() + v.std * rng.normal();
      out.push_back(v);
    }
    return out;
  }
};

/// A binomial rate's band: expected +/- 4 binomial standard deviations (a false failure once in ~16000).
void expect_rate(int hits, int trials_count, double expected, const char* what) {
  const double rate = static_cast<double>(hits) / trials_count;
  const double band = 4.0 * std::sqrt(expected * (1.0 - expected) / trials_count);
  EXPECT_NEAR(rate, expected, band) << what << ": " << hits << " of " << trials_count;
}

TEST(Distributions, ChiSquareQuantilesMatchThePrintedTable) {
  // NIST/SEMATECH e-Handbook of Statistical Methods, 1.3.6.7.4 "Critical values of the chi-square
  // distribution", 19 degrees of freedom: lower-tail 0.025 point 8.907 and upper-tail 0.025 point 32.852
  // (so 0.975 of the law below it); and 0.05 / 0.95: 10.117, 30.144. Printed to 3 decimals.
  EXPECT_NEAR(chi_squared_quantile(0.025, 19.0), 8.907, 6e-4);
  EXPECT_NEAR(chi_squared_quantile(0.975, 19.0), 32.852, 6e-4);
  EXPECT_NEAR(chi_squared_quantile(0.05, 19.0), 10.117, 6e-4);
  EXPECT_NEAR(chi_squared_quantile(0.95, 19.0), 30.144, 6e-4);
}

TEST(Distributions, StudentTTwoSidedPMatchesThePrintedTableAndClosedForms) {
  // NIST/SEMATECH e-Handbook 1.3.6.7.2 "Critical values of the Student's t distribution": the upper 0.025
  // point (two-sided 0.05) at 18 degrees of freedom is 2.101, at 10 it is 2.228; the upper 0.005 point
  // (two-sided 0.01) at 10 is 3.169. Printed to 3 decimals: the p at the printed point is within the
  // density times 5e-4 (< 3e-5 here) of the nominal.
  EXPECT_NEAR(student_t_two_sided_p(2.101, 18.0), 0.05, 5e-5);
  EXPECT_NEAR(student_t_two_sided_p(-2.101, 18.0), 0.05, 5e-5);
  EXPECT_NEAR(student_t_two_sided_p(2.228, 10.0), 0.05, 5e-5);
  EXPECT_NEAR(student_t_two_sided_p(3.169, 10.0), 0.01, 2e-5);
  // One degree of freedom is Cauchy's law: P(|T| >= t) = 1 - (2/pi) atan(t); at t = 1, 1/2; at sqrt(3), 1/3.
  EXPECT_NEAR(student_t_two_sided_p(1.0, 1.0), 0.5, 1e-13);
  EXPECT_NEAR(student_t_two_sided_p(std::sqrt(3.0), 1.0), 1.0 / 3.0, 1e-13);
  // Two degrees of freedom: P(|T| >= t) = 1 - t / sqrt(2 + t^2); at t = 1, 1 - 1/sqrt(3).
  EXPECT_NEAR(student_t_two_sided_p(1.0, 2.0), 1.0 - 1.0 / std::sqrt(3.0), 1e-13);
  EXPECT_DOUBLE_EQ(student_t_two_sided_p(0.0, 5.0), 1.0);
  EXPECT_EQ(student_t_two_sided_p(INFINITY, 5.0), 0.0);
  EXPECT_TRUE(std::isnan(student_t_two_sided_p(1.0, 0.0)));
}

TEST(Repeatability, ThreeRunsByHand) {
  // Runs (day, value, std): (0, 10, 1), (1, 12, 2), (2, 11, 1).
  const std::vector<RunValue> v = {{1, 0.0, 10.0, 1.0}, {2, 1.0, 12.0, 2.0}, {3, 2.0, 11.0, 1.0}};
  const Repeatability r = repeatability(v);
  EXPECT_EQ(r.runs, 3u);
  // Weights 1/std^2: 1, 1/4, 1; sum 9/4; sum w x = 10 + 3 + 11 = 24; mean = 24 / (9/4) = 32/3.
  EXPECT_NEAR(r.mean, 32.0 / 3.0, 1e-12);
  // chi2 = (10 - 32/3)^2 + (12 - 32/3)^2 / 4 + (11 - 32/3)^2 = 4/9 + 4/9 + 1/9 = 1; Birge ratio sqrt(1/2) <
  // 1, so the mean's std stays 1/sqrt(9/4) = 2/3.
  EXPECT_NEAR(r.mean_std, 2.0 / 3.0, 1e-12);
  // F(2, inf) test: 2 X = chi2 = 1 ~ chi2(2), whose tail is exp(-chi2/2) = exp(-1/2).
  ASSERT_TRUE(r.f_test_p);
  EXPECT_NEAR(*r.f_test_p, std::exp(-0.5), 1e-12);
  // Sample std: unweighted mean 11, deviations -1, 1, 0: s^2 = 2 / 2 = 1.
  ASSERT_TRUE(r.run_to_run_std);
  EXPECT_NEAR(*r.run_to_run_std, 1.0, 1e-12);
  // The 68.27 % interval: 2 s^2 / sigma^2 ~ chi2(2), whose quantile at q is -2 ln(1 - q); the tails are
  // (1 - 0.6827) / 2 = 0.15865 each: low = sqrt(2 / (-2 ln 0.15865)), high = sqrt(2 / (-2 ln 0.84135)).
  ASSERT_TRUE(r.run_to_run_std_low && r.run_to_run_std_high);
  EXPECT_NEAR(*r.run_to_run_std_low, std::sqrt(2.0 / (-2.0 * std::log(0.15865))), 1e-9);
  EXPECT_NEAR(*r.run_to_run_std_high, std::sqrt(2.0 / (-2.0 * std::log(0.84135))), 1e-9);
  // Stated sigma: sqrt((1 + 4 + 1) / 3) = sqrt(2); the ratio 1 / sqrt(2).
  EXPECT_NEAR(r.mean_stated_std, std::sqrt(2.0), 1e-12);
  ASSERT_TRUE(r.std_ratio);
  EXPECT_NEAR(*r.std_ratio, 1.0 / std::sqrt(2.0), 1e-12);
  // OLS: day mean 1, Stt = 2, Stx = (-1)(-1) + 0 + (1)(0) = 1: slope 1/2 per day. The line 11 + (t - 1)/2
  // gives 10.5, 11, 11.5; residuals -0.5, 1, -0.5; RSS 1.5 over n - 2 = 1: slope std sqrt(1.5 / 2).
  // t = 0.5 / sqrt(0.75) = 1/sqrt(3) with 1 degree of freedom (Cauchy): p = 1 - (2/pi) atan(1/sqrt(3)) = 2/3.
  ASSERT_TRUE(r.trend_per_day && r.trend_std && r.trend_p);
  EXPECT_NEAR(*r.trend_per_day, 0.5, 1e-12);
  EXPECT_NEAR(*r.trend_std, std::sqrt(0.75), 1e-12);
  EXPECT_NEAR(*r.trend_p, 2.0 / 3.0, 1e-12);
  // Individuals chart: moving ranges 2 and 1, mean 1.5; sigma 1.5 / 1.128; limits 11 -/+ 3 sigma.
  const double sigma = 1.5 / 1.128;
  ASSERT_TRUE(r.chart_sigma && r.limits);
  EXPECT_NEAR(*r.chart_sigma, sigma, 1e-12);
  EXPECT_NEAR((*r.limits)[0], 11.0 - 3.0 * sigma, 1e-12);
  EXPECT_NEAR((*r.limits)[1], 11.0 + 3.0 * sigma, 1e-12);
  EXPECT_TRUE(r.flagged.empty());
  // EWMA, lambda 0.2, from 11: 0.2*10 + 0.8*11 = 10.8; 0.2*12 + 0.8*10.8 = 11.04; 0.2*11 + 0.8*11.04
  // = 11.032. Half-widths 3 sigma sqrt(0.2/1.8 (1 - 0.8^(2i))): i = 1: sqrt(0.04) = 0.2; i = 2: sqrt(0.0656).
  ASSERT_EQ(r.ewma.size(), 3u);
  EXPECT_NEAR(r.ewma[0], 10.8, 1e-12);
  EXPECT_NEAR(r.ewma[1], 11.04, 1e-12);
  EXPECT_NEAR(r.ewma[2], 11.032, 1e-12);
  ASSERT_EQ(r.ewma_limits.size(), 3u);
  EXPECT_NEAR(r.ewma_limits[0][0], 11.0 - 3.0 * sigma * 0.2, 1e-12);
  EXPECT_NEAR(r.ewma_limits[1][1], 11.0 + 3.0 * sigma * std::sqrt(0.0656), 1e-12);
  EXPECT_TRUE(r.ewma_flagged.empty());
}

TEST(Repeatability, TheBirgeRatioWidensTheMeansStdWhenTheScatterExceedsTheStatedSigma) {
  // Two runs (0, 1) and (10, 1): mean 5; chi2 = 25 + 25 = 50 over 1 degree of freedom: Birge ratio sqrt(50);
  // the mean's std 1/sqrt(2) * sqrt(50) = 5. The F-test: chi2(1) tail at 50 is erfc(sqrt(50/2)) = erfc(5).
  const std::vector<RunValue> v = {{7, 100.0, 0.0, 1.0}, {9, 101.0, 10.0, 1.0}};
  const Repeatability r = repeatability(v);
  EXPECT_NEAR(r.mean, 5.0, 1e-12);
  EXPECT_NEAR(r.mean_std, 5.0, 1e-12);
  ASSERT_TRUE(r.f_test_p);
  EXPECT_NEAR(*r.f_test_p / std::erfc(5.0), 1.0, 1e-9);
  // Sample std sqrt(50); two runs give no trend.
  EXPECT_NEAR(*r.run_to_run_std, std::sqrt(50.0), 1e-12);
  EXPECT_FALSE(r.trend_per_day);
  EXPECT_FALSE(r.trend_std);
  EXPECT_FALSE(r.trend_p);
  // The charts exist from two runs: moving range 10, sigma 10/1.128; nothing outside 5 -/+ 26.6.
  ASSERT_TRUE(r.limits);
  EXPECT_NEAR((*r.limits)[1], 5.0 + 3.0 * 10.0 / 1.128, 1e-12);
  EXPECT_EQ(r.ewma.size(), 2u);
}

TEST(Repeatability, OneRunHasItsValueAndNothingElse) {
  const std::vector<RunValue> v = {{4, 100.0, 3.5, 0.25}};
  const Repeatability r = repeatability(v);
  EXPECT_EQ(r.runs, 1u);
  EXPECT_EQ(r.mean, 3.5);
  EXPECT_EQ(r.mean_std, 0.25);
  EXPECT_EQ(r.mean_stated_std, 0.25);
  EXPECT_FALSE(r.run_to_run_std || r.run_to_run_std_low || r.run_to_run_std_high || r.std_ratio ||
               r.f_test_p);
  EXPECT_FALSE(r.trend_per_day || r.trend_std || r.trend_p);
  EXPECT_FALSE(r.limits || r.chart_sigma);
  EXPECT_TRUE(r.flagged.empty() && r.ewma.empty() && r.ewma_limits.empty() && r.ewma_flagged.empty());
}

TEST(Repeatability, RunsOfOneDayHaveNoTrend) {
  const std::vector<RunValue> v = {{1, 5.0, 1.0, 0.1}, {2, 5.0, 1.2, 0.1}, {3, 5.0, 0.9, 0.1}};
  const Repeatability r = repeatability(v);
  EXPECT_FALSE(r.trend_per_day || r.trend_std || r.trend_p);
  EXPECT_TRUE(r.run_to_run_std && r.f_test_p && r.limits);
}

TEST(Repeatability, EqualValuesFlagNothingAndShowNoTrend) {
  // 0.1 is not a binary fraction: a mean summed as 0.1 + 0.1 + 0.1 and divided by 3 would differ from it.
  const std::vector<RunValue> v = {{1, 0.0, 0.1, 0.01}, {2, 1.0, 0.1, 0.01}, {3, 2.0, 0.1, 0.01}};
  const Repeatability r = repeatability(v);
  EXPECT_EQ(r.mean, 0.1);
  EXPECT_EQ(*r.run_to_run_std, 0.0);
  EXPECT_EQ(*r.trend_per_day, 0.0);
  EXPECT_EQ(*r.trend_p, 1.0);
  EXPECT_EQ(*r.chart_sigma, 0.0);
  EXPECT_TRUE(r.flagged.empty());
  EXPECT_TRUE(r.ewma_flagged.empty());
}

TEST(Repeatability, RefusesWhatNoHistoryHolds) {
  EXPECT_THROW(repeatability({}), std::invalid_argument);
  const auto refused = [](std::vector<RunValue> v, const char* key) {
    try {
      repeatability(v);
      ADD_FAILURE() << "accepted: " << key;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  refused({{1, 0.0, 1.0, 0.1}, {2, 1.0, 1.0, 0.0}}, "run 2 has a std of 0");
  refused({{1, 0.0, 1.0, -0.1}}, "run 1 has a std of -0.1");
  refused({{1, 0.0, 1.0, NAN}}, "std of nan");
  refused({{1, 0.0, 1.0, INFINITY}}, "std of inf");
  refused({{1, 0.0, NAN, 0.1}}, "run 1 has a value that is not finite");
  refused({{1, NAN, 1.0, 0.1}}, "run 1 has a date that is not finite");
  refused({{1, 2.0, 1.0, 0.1}, {2, 1.0, 1.0, 0.1}}, "date order");
  refused({{2, 1.0, 1.0, 0.1}, {1, 1.0, 1.0, 0.1}}, "date order");
  const std::vector<RunValue> ok = {{1, 0.0, 1.0, 0.1}};
  RepeatabilityOptions o;
  o.ewma_lambda = 0.0;
  EXPECT_THROW(repeatability(ok, o), std::invalid_argument);
  o = {};
  o.interval = 1.0;
  EXPECT_THROW(repeatability(ok, o), std::invalid_argument);
}

TEST(Repeatability, TheRunToRunStdsIntervalCoversTheTurnOnScatterAtItsRate) {
  // 20 runs whose bias is redrawn per run (tau = 2 sigma): the run-to-run std's truth is sqrt(tau^2 +
  // sigma^2), and its 68.27 % interval holds it in 68.27 % of histories.
  Generator g;
  g.sigma = 0.1;
  g.tau = 0.2;
  const double truth = std::hypot(g.tau, g.sigma);
  const int n = trials(2000, 400);
  int covered = 0, below = 0;
  for (int seed = 0; seed < n; ++seed) {
    const Repeatability r = repeatability(g.history(20, seed));
    if (*r.run_to_run_std_low <= truth && truth <= *r.run_to_run_std_high) ++covered;
    if (*r.run_to_run_std_high < truth) ++below;
  }
  std::printf("interval covers the truth in %d of %d histories; truth above it in %d\n", covered, n, below);
  expect_rate(covered, n, 0.6827, "covered");
  // The interval is equal-tailed: the truth lies above it in (1 - 0.6827) / 2 of histories.
  expect_rate(below, n, 0.15865, "truth above the interval");
}

TEST(Repeatability, TheFTestFlagsATurnOnScatterOfThreeSigma) {
  // One 20-run history with tau = 3 sigma: chi2 ~ 10 chi2(19), about 190 against 19 degrees of freedom.
  Generator g;
  g.tau = 3.0 * g.sigma;
  g.spread = 0.3;
  const Repeatability one = repeatability(g.history(20, 12345));
  EXPECT_LT(*one.f_test_p, 1e-3);
  EXPECT_GT(*one.std_ratio, 2.0);
  // And so in nearly all histories: p >= 1e-3 needs chi2(19) <= 43.8 / 10 (probability ~2e-5 at equal sigma).
  const int n = trials(1000, 200);
  int flagged = 0;
  for (int seed = 0; seed < n; ++seed)
    if (*repeatability(g.history(20, seed)).f_test_p < 1e-3) ++flagged;
  std::printf("tau = 3 sigma: p < 1e-3 in %d of %d histories (the one: p = %.3g, ratio %.2f)\n", flagged, n,
              *one.f_test_p, *one.std_ratio);
  EXPECT_GE(flagged, n - n / 100) << flagged << " of " << n;
}

/// The Kolmogorov-Smirnov statistic of p against the uniform law on [0, 1]: max |F_n(p) - p|.
double ks_uniform(std::vector<double> p) {
  std::sort(p.begin(), p.end());
  const double n = static_cast<double>(p.size());
  double d = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    d = std::max(d, static_cast<double>(i + 1) / n - p[i]);
    d = std::max(d, p[i] - static_cast<double>(i) / n);
  }
  return d;
}

TEST(Repeatability, WithoutTurnOnScatterTheFTestsPValuesAreUniform) {
  // The KS test's critical value at 1 % for n > 35 samples is 1.63 / sqrt(n) (F. J. Massey, "The
  // Kolmogorov-Smirnov test for goodness of fit", JASA 46 (1951), table 1; the asymptotic 1.628 / sqrt(n)).
  Generator g;
  g.spread = 0.5;  // unequal stated sigma: the F-test weighs each run by its own
  const int n = trials(400, 200);
  const double critical = 1.63 / std::sqrt(static_cast<double>(n));
  std::vector<double> p;
  for (int seed = 0; seed < n; ++seed) p.push_back(*repeatability(g.history(20, seed)).f_test_p);
  const double d = ks_uniform(p);
  std::printf("KS statistic of %d p-values: %.4f (1 %% critical %.4f)\n", n, d, critical);
  EXPECT_LT(d, critical);
  // The same test sees a turn-on scatter of one sigma (the p-values pile up near 0).
  g.tau = g.sigma;
  p.clear();
  for (int seed = 0; seed < n; ++seed) p.push_back(*repeatability(g.history(20, seed)).f_test_p);
  std::printf("with tau = sigma: KS statistic %.4f\n", ks_uniform(p));
  EXPECT_GT(ks_uniform(p), critical);
}

TEST(Repeatability, ATrendOfThreeSigmaPerSpanIsFoundAndNoneIsFoundAtTheTestsRate) {
  // 20 runs a week apart with a turn-on scatter (tau = sigma): the run-to-run sigma is sqrt(2) sigma, and the
  // trend moves the value by 3 of those over the span (19 weeks). Expected t ~ 3 sqrt(n (n+1) / (12 (n-1))) =
  // 4.07 with 18 degrees of freedom: found (p < 0.05, |t| > 2.101) in ~97 % of histories.
  Generator g;
  g.tau = g.sigma;
  const double run_sigma = std::hypot(g.tau, g.sigma);
  const double span = 19.0 * g.spacing_days;
  const int n = trials(1000, 200);
  Generator trend = g;
  trend.trend_per_day = 3.0 * run_sigma / span;
  int found = 0, found_without = 0, covered = 0;
  for (int seed = 0; seed < n; ++seed) {
    const Repeatability r = repeatability(trend.history(20, seed));
    if (*r.trend_p < 0.05 && *r.trend_per_day > 0) ++found;
    if (std::abs(*r.trend_per_day - trend.trend_per_day) <= *r.trend_std) ++covered;
    if (*repeatability(g.history(20, seed)).trend_p < 0.05) ++found_without;
  }
  std::printf("trend found in %d of %d; without a trend in %d; slope within its std in %d\n", found, n,
              found_without, covered);
  EXPECT_GE(found, n * 92 / 100) << found << " of " << n;
  expect_rate(found_without, n, 0.05, "trend found where there is none");
  // The slope's std is its scatter's: +/- 1 std holds the injected slope in ~68 % (t(18) within 1: 67 %).
  expect_rate(covered, n, 2.0 * (1.0 - 0.5 * student_t_two_sided_p(1.0, 18.0)) - 1.0, "slope within its std");
}

TEST(Repeatability, ShewhartFlagsARunOffsetBySixSigmaAndNoOther) {
  Generator g;
  const int n = trials(500, 100);
  int hit = 0, other = 0;
  for (int seed = 0; seed < n; ++seed) {
    std::vector<RunValue> v = g.history(20, seed);
    v[9].value += 6.0 * g.sigma;  // run id 10
    const Repeatability r = repeatability(v);
    if (std::find(r.flagged.begin(), r.flagged.end(), 10) != r.flagged.end()) ++hit;
    if (std::any_of(r.flagged.begin(), r.flagged.end(), [](std::int64_t id) { return id != 10; })) ++other;
  }
  // The outlier widens the moving ranges beside it (two of 19 near 6 sigma: the chart's sigma ~1.45 sigma,
  // the limits ~4.4 sigma from a centre 0.3 sigma towards it): flagged in most histories, another run in
  // almost none.
  std::printf("6 sigma outlier flagged in %d of %d; another run flagged in %d\n", hit, n, other);
  EXPECT_GE(hit, n * 85 / 100) << hit << " of " << n;
  EXPECT_LE(other, n / 100 + 1) << other << " of " << n;
  // And in one history, exactly that run.
  std::vector<RunValue> v = g.history(20, 7);
  v[9].value += 6.0 * g.sigma;
  EXPECT_EQ(repeatability(v).flagged, std::vector<std::int64_t>{10});
  EXPECT_TRUE(repeatability(g.history(20, 7)).flagged.empty());
}

TEST(Repeatability, EwmaFlagsASmallSustainedShiftThatShewhartMisses) {
  // 30 runs; from run 21 on the value is 2 sigma higher (a rig or unit that moved): the centre is 2/3 sigma
  // up, the last runs 4/3 sigma above it; the individuals chart's limits are ~3 sigma away, the EWMA's
  // (lambda 0.2) ~1 sigma. Measured over 500 seeds: the EWMA flags a shifted run in 74 %, the individuals
  // chart in 36 %; the bands are those rates -/+ 4 binomial sigma. (The centre lies between the two levels,
  // so in half the histories the EWMA also flags the runs before the step, low.)
  Generator g;
  const int n = trials(500, 100);
  int ewma = 0, shewhart = 0, ewma_before = 0;
  for (int seed = 0; seed < n; ++seed) {
    std::vector<RunValue> v = g.history(30, seed);
    for (std::size_t i = 20; i < v.size(); ++i) v[i].value += 2.0 * g.sigma;
    const Repeatability r = repeatability(v);
    if (std::any_of(r.ewma_flagged.begin(), r.ewma_flagged.end(), [](std::int64_t id) { return id > 20; }))
      ++ewma;
    if (std::any_of(r.flagged.begin(), r.flagged.end(), [](std::int64_t id) { return id > 20; })) ++shewhart;
    if (!r.ewma_flagged.empty() && r.ewma_flagged.front() <= 20) ++ewma_before;
  }
  std::printf(
      "2 sigma shift of the last 10 of 30 runs: EWMA flags it in %d of %d, Shewhart in %d; EWMA flags "
      "an earlier run first in %d\n",
      ewma, n, shewhart, ewma_before);
  EXPECT_GE(ewma, n * 66 / 100) << ewma << " of " << n;
  EXPECT_LE(shewhart, n * 45 / 100) << shewhart << " of " << n;
  EXPECT_GT(ewma, shewhart + n / 4);
}

}  // namespace
}  // namespace gyrocal
