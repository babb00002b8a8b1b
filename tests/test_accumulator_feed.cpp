// The accumulation on a thread of its own (reduce/accumulator_feed.hpp): an accumulator fed through the
// worker thread gives the very numbers it gives when fed on the caller's thread, whatever the batches' cuts,
// with the outlier rule, gaps and several dwells' accumulators in turn.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <memory>
#include <random>
#include <vector>

#include "gyrocal/core/units.hpp"
#include "gyrocal/reduce/accumulator_feed.hpp"
#include "gyrocal/reduce/dwell_accumulator.hpp"

namespace gyrocal {
namespace {

struct Sample {
  double t, gamma, value;
  bool gap_before;
};

/// A spinning dwell's output: harmonics of gamma, a drift, white noise, a few spikes and gaps.
std::vector<Sample> dwell_samples(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<Sample> out;
  const double dt = 0.005, rate = 9.9;
  double t = 100.0;
  for (std::size_t i = 0; i < n; ++i) {
    const bool gap = i > 0 && i % 7919 == 0;
    t += gap ? 3.0 * dt : dt;
    const double gamma = rate * (t - 100.0);
    double v = 12.0 + 3.0 * std::cos(gamma) - 2.0 * std::sin(2.0 * gamma) + 0.7 * std::cos(3.0 * gamma) +
               0.01 * (t - 100.0) + noise(rng);
    if (i % 10007 == 5000) v += 40.0;  // a spike
    out.push_back({t, gamma, v, gap});
  }
  return out;
}

DwellAccumulator make_accumulator(const std::vector<Sample>& s) {
  const std::vector<double> gammas = {0.0, kPi / 2, kPi, 3 * kPi / 2};
  const double duration = s.back().t - s.front().t + 0.005;
  return DwellAccumulator(ReduceOptions{}, gammas, false, 1, duration, true);
}

void expect_same(const DwellValues& a, const DwellValues& b) {
  ASSERT_EQ(a.value.size(), b.value.size());
  for (std::size_t k = 0; k < a.value.size(); ++k) {
    EXPECT_EQ(a.value[k], b.value[k]) << k;
    EXPECT_EQ(a.std_err[k], b.std_err[k]) << k;
    EXPECT_EQ(a.samples[k], b.samples[k]) << k;
  }
  EXPECT_EQ(a.outliers, b.outliers);
  EXPECT_EQ(a.outlier_samples, b.outlier_samples);
  EXPECT_EQ(a.revolutions, b.revolutions);
  EXPECT_EQ(a.dof, b.dof);
  EXPECT_EQ(a.level, b.level);
}

TEST(AccumulatorFeed, GivesTheSameNumbersAsTheCallersThreadForSeveralDwellsInTurn) {
  const std::vector<Sample> first = dwell_samples(50000, 1), second = dwell_samples(30001, 2);
  DwellAccumulator direct_a = make_accumulator(first), direct_b = make_accumulator(second);
  DwellAccumulator fed_a = make_accumulator(first), fed_b = make_accumulator(second);
  const auto feed_directly = [](DwellAccumulator& acc, const std::vector<Sample>& s) {
    for (const Sample& x : s) {
      if (x.gap_before) acc.break_revolution();
      acc.add(x.t, x.gamma, &x.value);
    }
  };
  feed_directly(direct_a, first);
  feed_directly(direct_b, second);
  {
    AccumulatorFeed feed;
    // The two dwells' samples alternate in runs that do not match the feed's batches, as they would if a
    // reducer fed two accumulators in turn.
    std::size_t i = 0, j = 0;
    while (i < first.size() || j < second.size()) {
      for (std::size_t k = 0; k < 3001 && i < first.size(); ++k, ++i) {
        if (first[i].gap_before) feed.break_revolution({&fed_a, 1});
        feed.add({&fed_a, 1}, first[i].t, first[i].gamma, &first[i].value);
      }
      for (std::size_t k = 0; k < 5003 && j < second.size(); ++k, ++j) {
        if (second[j].gap_before) feed.break_revolution({&fed_b, 1});
        feed.add({&fed_b, 1}, second[j].t, second[j].gamma, &second[j].value);
      }
    }
    feed.sync();
    EXPECT_EQ(fed_a.samples(), first.size());
    EXPECT_EQ(fed_b.samples(), second.size());
  }
  const DwellValues a = direct_a.finish(0), b = direct_b.finish(0);
  EXPECT_GT(a.outliers, 0u);  // the spikes were found, so the outlier rule ran on the worker
  expect_same(fed_a.finish(0), a);
  expect_same(fed_b.finish(0), b);
}

TEST(AccumulatorFeed, FeedsEachAccumulatorOfAGroupItsOwnColumn) {
  // A dwell of three output columns (an IMU's channels): each row's k-th value goes to the k-th accumulator,
  // with the gaps' breaks to all three, across batches cut between rows (3 does not divide kBatchSamples).
  // Each column has its own spikes (column 2 none), so each accumulator runs its own outlier rule.
  const std::vector<Sample> s0 = dwell_samples(30000, 5), s1 = dwell_samples(30000, 6);
  std::vector<Sample> s2 = dwell_samples(30000, 7);
  for (std::size_t i = 5000; i < s2.size(); i += 10007) s2[i].value -= 40.0;  // its spikes taken away
  std::vector<DwellAccumulator> direct, fed;
  for (int k = 0; k < 3; ++k) {
    direct.push_back(make_accumulator(s0));
    fed.push_back(make_accumulator(s0));
  }
  {
    AccumulatorFeed feed;
    for (std::size_t i = 0; i < s0.size(); ++i) {
      const double values[3] = {s0[i].value, s1[i].value, s2[i].value};
      if (s0[i].gap_before) {
        for (DwellAccumulator& a : direct) a.break_revolution();
        feed.break_revolution(fed);
      }
      for (std::size_t k = 0; k < 3; ++k) direct[k].add(s0[i].t, s0[i].gamma, &values[k]);
      feed.add(fed, s0[i].t, s0[i].gamma, values);
    }
    feed.sync();
  }
  std::vector<DwellValues> want;
  for (std::size_t k = 0; k < 3; ++k) {
    want.push_back(direct[k].finish(0));
    SCOPED_TRACE(k);
    expect_same(fed[k].finish(0), want.back());
  }
  EXPECT_GT(want[0].outliers, 0u);
  EXPECT_EQ(want[2].outliers, 0u);                // its own rule: the other columns' spikes are not its
  EXPECT_NE(want[0].value[0], want[1].value[0]);  // each its own column
}

TEST(AccumulatorFeed, WithoutAThreadMakesTheCallsAtOnce) {
  // The Monte Carlo's reducers (one a trial, the trials on every core) feed their accumulators inline.
  const std::vector<Sample> s = dwell_samples(20000, 4);
  DwellAccumulator direct = make_accumulator(s), fed = make_accumulator(s);
  AccumulatorFeed feed(false);
  for (const Sample& x : s) {
    if (x.gap_before) {
      direct.break_revolution();
      feed.break_revolution({&fed, 1});
    }
    direct.add(x.t, x.gamma, &x.value);
    feed.add({&fed, 1}, x.t, x.gamma, &x.value);
    ASSERT_EQ(fed.samples(), direct.samples());  // no sync needed: nothing waits
  }
  feed.sync();
  expect_same(fed.finish(0), direct.finish(0));
}

TEST(AccumulatorFeed, CanBeDestroyedWithWorkInFlight) {
  // The reducer's feed is destroyed first when a record is refused mid-dwell: its worker stops before the
  // accumulators it was feeding go away (the sanitizer build checks that nothing is touched after).
  const std::vector<Sample> s = dwell_samples(40000, 3);
  auto acc = std::make_unique<DwellAccumulator>(make_accumulator(s));
  {
    AccumulatorFeed feed;
    for (const Sample& x : s) feed.add({acc.get(), 1}, x.t, x.gamma, &x.value);
  }
  acc.reset();
  SUCCEED();
}

}  // namespace
}  // namespace gyrocal
