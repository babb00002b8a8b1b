// The test timeline (plan/timeline.hpp): the plan's intervals, whole revolutions, settling, gamma coverage,
// rate-0 indexing, and motion that a real machine can make (continuous angles and main rate, bounded rates).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <gtest/gtest.h>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/plan/positions.hpp"
#include "gyrocal/plan/timeline.hpp"

namespace gyrocal {
namespace {

constexpr double kTwoPi = 2.0 * kPi;

/// x modulo 2 pi, in (-pi, pi].
double wrap_pi(double x) {
  return x - kTwoPi * std::round(x / kTwoPi);
}

/// A reduced test through every kind of transition: spinning, stopped, spinning the other way.
TestSpec mixed_test() {
  TestSpec test;
  test.revolutions = 3;
  test.settle_s = 0.5;
  test.rates_rad_s = {9.9, 0.0, -5.0};
  return test;
}

CentrifugeModel default_model() {
  return default_scenario().model();
}

TEST(Timeline, DefaultTestHasFourDwellsCoveringTheSixteenPositions) {
  const Scenario s = default_scenario();
  const Timeline timeline = make_timeline(s.test, s.model());
  ASSERT_EQ(timeline.measurements.size(), 4u);
  std::vector<int> covered;
  for (const MeasurementInterval& m : timeline.measurements) {
    EXPECT_EQ(m.kind, SegmentKind::kDwell);
    for (std::size_t k = 0; k < s.test.gamma_rad.size(); ++k) covered.push_back(m.position_index + int(k));
  }
  const std::vector<Position> positions = test_positions(s.test);
  ASSERT_EQ(covered.size(), 16u);
  for (std::size_t i = 0; i < covered.size(); ++i) {
    const Position& p = positions[std::size_t(covered[i] - 1)];
    EXPECT_EQ(p.index, int(i) + 1);
    const MeasurementInterval& m = timeline.measurements[i / 4];
    EXPECT_EQ(p.rate_rad_s, m.rate_rad_s);
    EXPECT_EQ(p.beta_rad, m.beta_rad);
  }
}

TEST(Timeline, RateZeroSetHasOneHoldPerBetaAndGamma) {
  TestSpec test = mixed_test();
  test.rates_rad_s = {0.0};
  const Timeline timeline = make_timeline(test, default_model());
  ASSERT_EQ(timeline.measurements.size(), 16u);
  const std::vector<Position> positions = test_positions(test);
  // No non-zero rate: the hold lasts one dwell at the centrifuge's rate.
  EXPECT_EQ(timeline.reference_rate_rad_s, 9.9);
  for (std::size_t i = 0; i < 16; ++i) {
    const MeasurementInterval& m = timeline.measurements[i];
    EXPECT_EQ(m.kind, SegmentKind::kHold);
    EXPECT_EQ(m.position_index, positions[i].index);
    EXPECT_EQ(m.beta_rad, positions[i].beta_rad);
    EXPECT_EQ(m.gamma_rad, positions[i].gamma_rad);
    EXPECT_NEAR(m.end_s - m.start_s, 3 * kTwoPi / 9.9, 1e-12);
  }
}

TEST(Timeline, SegmentsAreContiguousFromZeroToTheDuration) {
  const Timeline timeline = make_timeline(mixed_test(), default_model());
  ASSERT_FALSE(timeline.segments.empty());
  EXPECT_EQ(timeline.segments.front().start_s, 0.0);
  for (std::size_t i = 1; i < timeline.segments.size(); ++i) {
    EXPECT_EQ(timeline.segments[i].start_s, timeline.segments[i - 1].end_s);
    EXPECT_GT(timeline.segments[i].end_s, timeline.segments[i].start_s);
  }
  EXPECT_EQ(timeline.segments.back().end_s, timeline.duration_s);
}

TEST(Timeline, FirstDwellFollowsSectionThreeFromTimeZero) {
  const CentrifugeModel model = default_model();
  const TestSpec test = mixed_test();
  const Timeline timeline = make_timeline(test, model);
  const MeasurementInterval& first = timeline.measurements.front();
  EXPECT_EQ(first.start_s, test.settle_s);  // no transition before the first settle
  for (double t = 0.0; t < first.end_s; t += 0.0137) {
    const JointState j = joint_state_at(timeline, t);
    const JointState expected = spinning_joint_state(model, 9.9, test.beta_rad[0], t);
    EXPECT_EQ(j.main_angle_rad, expected.main_angle_rad);
    EXPECT_EQ(j.counter_angle_rad, expected.counter_angle_rad);
    EXPECT_EQ(j.counter_rate_rad_s, expected.counter_rate_rad_s);
    EXPECT_EQ(j.position_angle_rad, expected.position_angle_rad);
  }
}

TEST(Timeline, DwellsAreWholeRevolutionsAtASteadyRateAfterASettle) {
  const CentrifugeModel model = default_model();
  const TestSpec test = mixed_test();
  const Timeline timeline = make_timeline(test, model);
  const double delta_omega = model.errors().counter_rate_mismatch_rad_s;
  int dwells = 0;
  for (const MeasurementInterval& m : timeline.measurements) {
    // The segment before each measurement is a settle of settle_s in the same steady state.
    const auto it = std::find_if(timeline.segments.begin(), timeline.segments.end(),
                                 [&](const Segment& s) { return s.start_s == m.start_s; });
    ASSERT_NE(it, timeline.segments.begin());
    EXPECT_EQ(it->kind, m.kind);
    EXPECT_EQ((it - 1)->kind, SegmentKind::kSettle);
    EXPECT_NEAR((it - 1)->end_s - (it - 1)->start_s, test.settle_s, 1e-12);
    for (double t = (it - 1)->start_s; t < m.end_s; t += 0.01) {
      const JointState j = joint_state_at(timeline, t);
      EXPECT_EQ(j.main_rate_rad_s, m.rate_rad_s);
      EXPECT_EQ(j.main_accel_rad_s2, 0.0);
      EXPECT_EQ(j.position_angle_rad, m.beta_rad);
      EXPECT_EQ(j.position_rate_rad_s, 0.0);
      if (m.kind == SegmentKind::kDwell) {
        // The counter platform is servoed: psi_r = -theta + psi0 + delta_omega t (modulo 2 pi).
        EXPECT_NEAR(wrap_pi(j.counter_angle_rad + j.main_angle_rad - timeline.psi0_rad - delta_omega * t),
                    0.0, 1e-9);
        EXPECT_EQ(j.counter_rate_rad_s, -m.rate_rad_s + delta_omega);
      }
    }
    if (m.kind != SegmentKind::kDwell) continue;
    ++dwells;
    const JointState start = joint_state_at(timeline, m.start_s);
    const JointState end = joint_state_at(timeline, m.end_s);
    EXPECT_NEAR(end.main_angle_rad - start.main_angle_rad,
                std::copysign(test.revolutions * kTwoPi, m.rate_rad_s), 1e-9);
    // Every gamma of the plan passes at least revolutions - 1 times (gamma turns at omega - delta omega).
    const double gamma_start = start.gamma_rad(), gamma_end = end.gamma_rad();
    for (const double gamma : test.gamma_rad) {
      const double lo = std::min(gamma_start, gamma_end), hi = std::max(gamma_start, gamma_end);
      const double passes = std::floor((hi - gamma) / kTwoPi) - std::floor((lo - gamma) / kTwoPi);
      EXPECT_GE(passes, test.revolutions - 1) << "gamma " << gamma;
    }
  }
  EXPECT_EQ(dwells, 8);
}

TEST(Timeline, HoldsIndexTheCounterPlatformToMinusGamma) {
  const TestSpec test = mixed_test();
  const Timeline timeline = make_timeline(test, default_model());
  int holds = 0;
  for (const MeasurementInterval& m : timeline.measurements) {
    if (m.kind != SegmentKind::kHold) continue;
    ++holds;
    EXPECT_EQ(m.rate_rad_s, 0.0);
    EXPECT_NEAR(m.end_s - m.start_s, test.revolutions * kTwoPi / 9.9, 1e-12);
    for (double t = m.start_s; t < m.end_s; t += 0.05) {
      const JointState j = joint_state_at(timeline, t);
      EXPECT_NEAR(wrap_pi(j.counter_angle_rad + m.gamma_rad), 0.0, 1e-12);
      EXPECT_EQ(j.counter_rate_rad_s, 0.0);
      EXPECT_EQ(j.main_rate_rad_s, 0.0);
    }
  }
  EXPECT_EQ(holds, 16);
}

TEST(Timeline, MotionIsContinuousAndWithinTheLimits) {
  const CentrifugeModel model = default_model();
  const MotionLimits limits;
  const Timeline timeline = make_timeline(mixed_test(), model);
  const double delta_omega = std::abs(model.errors().counter_rate_mismatch_rad_s);
  // At every boundary the segments on both sides agree: angles, the main rate and beta's rate exactly up to
  // rounding, the counter platform's rate up to delta omega (where its servo takes over or lets go).
  for (std::size_t i = 1; i < timeline.segments.size(); ++i) {
    const double t = timeline.segments[i].start_s;
    const JointState before = joint_state_at(timeline, std::nextafter(t, 0.0));
    const JointState after = joint_state_at(timeline, t);
    SCOPED_TRACE(testing::Message() << "boundary " << i << " at t = " << t);
    EXPECT_NEAR(before.main_angle_rad, after.main_angle_rad, 1e-9);
    EXPECT_NEAR(before.main_rate_rad_s, after.main_rate_rad_s, 1e-9);
    EXPECT_NEAR(before.counter_angle_rad, after.counter_angle_rad, 1e-9);
    EXPECT_NEAR(before.counter_rate_rad_s, after.counter_rate_rad_s, delta_omega + 1e-9);
    EXPECT_NEAR(before.position_angle_rad, after.position_angle_rad, 1e-9);
    EXPECT_NEAR(before.position_rate_rad_s, after.position_rate_rad_s, 1e-9);
  }
  // Everywhere: rates and accelerations within the limits, and each angle's change between two instants
  // within what its rates allow.
  const double dt = 1e-3;
  JointState previous = joint_state_at(timeline, 0.0);
  for (double t = dt; t < timeline.duration_s; t += dt) {
    const JointState j = joint_state_at(timeline, t);
    EXPECT_LE(std::abs(j.main_accel_rad_s2), limits.main_accel_rad_s2);
    EXPECT_LE(std::abs(j.position_rate_rad_s), limits.platform_rate_rad_s * (1 + 1e-12));
    EXPECT_LE(std::abs(j.position_accel_rad_s2), limits.platform_accel_rad_s2 * (1 + 1e-12));
    EXPECT_LE(std::abs(j.main_rate_rad_s), 9.9 + 1e-12);
    if (j.main_rate_rad_s == 0.0) {
      EXPECT_LE(std::abs(j.counter_rate_rad_s), limits.platform_rate_rad_s + delta_omega);
    }
    const auto bound = [dt](double rate0, double rate1, double accel) {
      return std::max(std::abs(rate0), std::abs(rate1)) * dt + 0.5 * std::abs(accel) * dt * dt + 1e-9;
    };
    EXPECT_LE(std::abs(j.main_angle_rad - previous.main_angle_rad),
              bound(previous.main_rate_rad_s, j.main_rate_rad_s, limits.main_accel_rad_s2));
    EXPECT_LE(std::abs(j.main_rate_rad_s - previous.main_rate_rad_s), limits.main_accel_rad_s2 * dt + 1e-9);
    EXPECT_LE(std::abs(j.counter_angle_rad - previous.counter_angle_rad),
              bound(previous.counter_rate_rad_s, j.counter_rate_rad_s,
                    std::max(limits.platform_accel_rad_s2, limits.main_accel_rad_s2)));
    EXPECT_LE(std::abs(j.position_angle_rad - previous.position_angle_rad),
              limits.platform_rate_rad_s * dt + 1e-12);
    previous = j;
  }
}

TEST(Timeline, StateIsExactForThePlatformsProfile) {
  // Rates and accelerations are the derivatives of the angles: central differences agree everywhere
  // except within h of a change of acceleration.
  const Timeline timeline = make_timeline(mixed_test(), default_model());
  const double h = 1e-4;
  for (const Segment& s : timeline.segments) {
    if (s.kind != SegmentKind::kPositionMove && s.kind != SegmentKind::kCounterMove &&
        s.kind != SegmentKind::kMainRamp) {
      continue;
    }
    for (int i = 1; i < 20; ++i) {
      const double t = s.start_s + (s.end_s - s.start_s) * i / 20.0;
      const JointState a = joint_state_at(timeline, t - h), b = joint_state_at(timeline, t),
                       c = joint_state_at(timeline, t + h);
      if (a.position_accel_rad_s2 != c.position_accel_rad_s2 ||
          a.counter_accel_rad_s2 != c.counter_accel_rad_s2) {
        continue;
      }
      EXPECT_NEAR((c.main_angle_rad - a.main_angle_rad) / (2 * h), b.main_rate_rad_s, 1e-6);
      EXPECT_NEAR((c.main_rate_rad_s - a.main_rate_rad_s) / (2 * h), b.main_accel_rad_s2, 1e-6);
      EXPECT_NEAR((c.position_angle_rad - a.position_angle_rad) / (2 * h), b.position_rate_rad_s, 1e-6);
      EXPECT_NEAR((c.position_rate_rad_s - a.position_rate_rad_s) / (2 * h), b.position_accel_rad_s2, 1e-6);
      EXPECT_NEAR((c.counter_angle_rad - a.counter_angle_rad) / (2 * h), b.counter_rate_rad_s, 1e-6);
      EXPECT_NEAR((c.counter_rate_rad_s - a.counter_rate_rad_s) / (2 * h), b.counter_accel_rad_s2, 1e-6);
    }
  }
}

TEST(Timeline, SampleCountHoldsEverySampleBeforeTheEnd) {
  const TestSpec test = mixed_test();
  const Timeline timeline = make_timeline(test, default_model());
  for (const double fs : {50.0, 200.0, 333.3}) {
    const std::uint64_t n = sample_count(timeline, fs);
    EXPECT_LT(static_cast<double>(n - 1) / fs, timeline.duration_s);
    EXPECT_GE(static_cast<double>(n) / fs, timeline.duration_s);
  }
}

TEST(Timeline, RefusesATestThatCannotBePlanned) {
  const CentrifugeModel model = default_model();
  TestSpec test = mixed_test();
  test.beta_rad.clear();
  EXPECT_THROW(make_timeline(test, model), Error);
  test = mixed_test();
  test.rates_rad_s = {0.0};
  CentrifugeGeometry stopped;
  stopped.rate_rad_s = 0.0;
  EXPECT_THROW(make_timeline(test, CentrifugeModel(Site{}, stopped, CentrifugeErrors{})), Error);
  CentrifugeErrors fast_drift;
  fast_drift.counter_rate_mismatch_rad_s = 1.0;  // faster than the platform can follow
  EXPECT_THROW(make_timeline(mixed_test(), CentrifugeModel(Site{}, CentrifugeGeometry{}, fast_drift)), Error);
}

}  // namespace
}  // namespace gyrocal
