// `plan` at a cost independent of the number of revolutions (issue 17, item 3): the model terms of a
// planned dwell in closed form equal their sum over every sample, and a long plan's predictions follow from a
// short one's as the sums over revolutions say.
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/model_terms.hpp"
#include "gyrocal/identify/planned_model_terms.hpp"

namespace gyrocal {
namespace {

TEST(PlannedChannels, GeometricPowerSumsEqualTheirTerms) {
  // Direct sums in long double against the closed forms, over phases from exact resonance (0 and 2 pi)
  // through the heading's slow drift (n x ~ 1e-6 .. 3) to the harmonics' steps.
  for (const double n : {1.0, 2.0, 7.0, 1000.0, 25000.0})
    for (const double x : {0.0, 2.0 * kPi, -4.0 * kPi, 1e-12, -3e-9, 1e-7, 4e-5, 1e-3, 0.0495, 0.7, 3.14159,
                           -2.5, 2.0 * kPi + 1e-9}) {
      std::complex<long double> s0 = 0, s1 = 0;
      for (long i = 0; i < static_cast<long>(n); ++i) {
        const std::complex<long double> z(std::cos(static_cast<long double>(x) * i),
                                          std::sin(static_cast<long double>(x) * i));
        s0 += z;
        s1 += static_cast<long double>(i) * z;
      }
      const auto [c0, c1] = geometric_power_sums(x, n);
      const double scale0 = n, scale1 = n * n;
      EXPECT_LT(std::abs(std::complex<double>(s0) - c0), 1e-13 * scale0) << "n " << n << " x " << x;
      EXPECT_LT(std::abs(std::complex<double>(s1) - c1), 1e-13 * scale1) << "n " << n << " x " << x;
    }
}

/// The same reduction with each planned dwell's samples given as one stretch: reduce_model_terms then
/// evaluates the model on every sample and reduces it by the accumulator, the route of a calibration.
Reduction as_one_stretch(Reduction r) {
  for (Dwell& d : r.dwells) {
    TimeStretch s;
    s.first_time_s = d.first_time_s;
    s.count = d.samples;
    s.interval_s = d.sample_interval_s;
    s.main_at_first_rad = d.main.at_first_rad;
    s.counter_at_first_rad = d.counter.at_first_rad;
    d.stretches = {s};
  }
  return r;
}

void expect_model_terms_equal(const Scenario& s, const std::string& what) {
  const Reduction r = planned_reduction(s);
  const CentrifugeModel model = s.model();
  const ReduceOptions ro;
  const std::vector<PositionModelTerms> closed = reduce_model_terms(r, model, ro);
  const std::vector<PositionModelTerms> summed = reduce_model_terms(as_one_stretch(r), model, ro);
  ASSERT_EQ(closed.size(), summed.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < closed.size(); ++i) {
    const auto check = [&](double a, double b, double scale, const char* name) {
      const double rel = std::abs(a - b) / scale;
      worst = std::max(worst, rel);
      EXPECT_LT(rel, 1e-9) << what << ": position " << i << " " << name << " " << a << " vs " << b;
    };
    // A rate relative to the Earth rate (15 deg/h) or itself if larger (a counter rate offset's 5e4 deg/h),
    // the regressors to their largest at the position.
    const auto rate = [&](double a, double b, const char* name) {
      check(a, b, std::max({15.0, std::abs(a), std::abs(b)}), name);
    };
    rate(closed[i].omega_exact_deg_h, summed[i].omega_exact_deg_h, "omega exact");
    rate(closed[i].omega_nominal_deg_h, summed[i].omega_nominal_deg_h, "omega nominal");
    rate(closed[i].omega_seed_deg_h, summed[i].omega_seed_deg_h, "omega seed");
    rate(closed[i].omega_O_exact_deg_h, summed[i].omega_O_exact_deg_h, "omega O");
    rate(closed[i].omega_S_exact_deg_h, summed[i].omega_S_exact_deg_h, "omega S");
    double largest = 1.0;
    for (double v : summed[i].regressors_exact) largest = std::max(largest, std::abs(v));
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
      check(closed[i].regressors_exact[k], summed[i].regressors_exact[k], largest, "regressor exact");
      check(closed[i].regressors_nominal[k], summed[i].regressors_nominal[k], largest, "regressor nominal");
    }
  }
  std::printf("%s: largest relative difference %.3g\n", what.c_str(), worst);
}

/// A machine with large errors of every kind: harmonics up to 3 of every joint, runouts, a lever arm.
Scenario large_errors() {
  Scenario s = default_scenario();
  CentrifugeErrors& e = s.errors;
  e.base_tilt_x_rad = 20 * kArcsecToRad;
  e.main_perpendicularity_y_rad = -15 * kArcsecToRad;
  e.main_wobble_x_rad.terms = {{1, 5 * kArcsecToRad, 0.3}, {3, 2 * kArcsecToRad, 1.1}};
  e.main_wobble_y_rad.terms = {{2, 4 * kArcsecToRad, -0.7}};
  e.main_runout_x_m.terms = {{1, 2e-5, 0.2}, {3, 1e-5, 0.0}};
  e.counter_perpendicularity_x_rad = 30 * kArcsecToRad;
  e.counter_wobble_x_rad.terms = {{1, 3 * kArcsecToRad, 0.4}, {3, 6 * kArcsecToRad, 2.0}};
  e.counter_wobble_y_rad.terms = {{2, 8 * kArcsecToRad, 1.2}};
  e.position_wobble_x_rad.terms = {{3, 5 * kArcsecToRad, 0.5}};
  e.position_angle_error_rad = 10 * kArcsecToRad;
  e.mount_misalignment_rad = Eigen::Vector3d(20, -30, 10) * kArcsecToRad;
  e.lever_arm_m = Eigen::Vector3d(0.01, -0.02, 0.015);
  e.radius_error_m = 1e-3;
  return s;
}

TEST(PlannedChannels, EqualTheSumOverEverySample) {
  // The closed form against the accumulator fed every sample, model term by model term, within 1e-9 relative
  // (it gives ~1e-11: the rounding of omega_O and omega_S, differences of two 2e6 deg/h rates).
  Scenario s = default_scenario();
  s.test.revolutions = 20;
  s.test.sample_rate_hz = 100.0;
  expect_model_terms_equal(s, "default machine");
  Scenario big = large_errors();
  big.test = s.test;
  big.test.rates_rad_s = {9.9, 4.95, 0.0};  // two speeds and a static set
  expect_model_terms_equal(big, "large errors, two speeds and static holds");
  // The heading turning within a dwell: a counter rate offset of both signs (a rate platform, docs/physics.md
  // section 15) and a rate mismatch that turns the platform by 0.4 rad over a dwell.
  Scenario offsets = big;
  offsets.test.rates_rad_s = {9.9, 0.0};
  offsets.test.counter_rate_offsets_rad_s = {0.0, 0.25, -0.25};
  expect_model_terms_equal(offsets, "counter rate offsets");
  Scenario drifting = big;
  drifting.errors.counter_rate_mismatch_rad_s = 3e-2;
  expect_model_terms_equal(drifting, "a platform heading drift of 3e-2 rad/s");
  Scenario window = s;
  // A window mean is not in closed form: the same path as before, every sample.
  ReduceOptions ro;
  ro.method = ReduceOptions::Method::kWindowMean;
  const Reduction r = planned_reduction(window);
  std::vector<DwellValues> out;
  EXPECT_FALSE(planned_dwell_model_terms(
      r.dwells[0], ro, 1, [](double, double, double* v) { *v = 1.0; }, out));
}

/// The predictions of `plan` for the default scenario at `revolutions` per dwell.
CalibrationResult plan_of(int revolutions) {
  Scenario s = default_scenario();
  s.test.revolutions = revolutions;
  return predict_calibration(s, CalibrationOptions{});
}

TEST(PlanScaling, TwoMillionRevolutionsScaleAsTheSums) {
  // White noise: each dwell's reduced values are least-squares fits to n samples, whose variance is 1/n
  // times a factor set by the basis' mean squares (1 for the constant, 1/2 for each harmonic, 1/12 for the
  // drift); the harmonics' and the drift's cross sums over a dwell are O(1), not O(n), so they move the
  // factor by O(1/n) (n = 25,387 samples per dwell at 200 revolutions: ~1e-4). The estimates are linear in
  // the positions with weights that scale alike, so every standard uncertainty scales as 1/sqrt(revolutions)
  // within that, here sqrt(200 / 2e6) = 0.01, and the noise-free estimates stay the truth (to the rounding of
  // the identification's sums, which grows with n: 5e-8 relative at 2e6 revolutions, as it was 4e-11 at 200
  // before the closed form; below a hundredth of their standard uncertainty). The 2e6-revolution
  // plan (5e8 samples per dwell, 50 days of test) is summed in closed form; its every-sample sum would take
  // minutes (issue 17).
  const CalibrationResult small = plan_of(200), big = plan_of(2000000);
  const double scale = std::sqrt(200.0 / 2e6);
  ASSERT_EQ(small.coefficients.size(), big.coefficients.size());
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    const CoefficientEstimate &a = small.coefficients[k], &b = big.coefficients[k];
    ASSERT_EQ(a.identifiable, b.identifiable) << kCoefficientNames[k];
    if (!a.identifiable) continue;
    EXPECT_NEAR(b.value, a.value, 1e-2 * b.std) << kCoefficientNames[k];
    EXPECT_NEAR(b.std / (a.std * scale), 1.0, 1e-4) << kCoefficientNames[k];
    std::printf("%s: std %.6g (200) %.6g (2e6), ratio / sqrt(200/2e6) - 1 = %.2g\n",
                kCoefficientNames[k].data(), a.std, b.std, b.std / (a.std * scale) - 1.0);
  }
  ASSERT_EQ(small.combinations.size(), big.combinations.size());
  for (std::size_t i = 0; i < small.combinations.size(); ++i) {
    EXPECT_NEAR(big.combinations[i].value, small.combinations[i].value, 1e-2 * big.combinations[i].std)
        << small.combinations[i].name;
    EXPECT_NEAR(big.combinations[i].std / (small.combinations[i].std * scale), 1.0, 1e-4)
        << small.combinations[i].name;
  }
}

}  // namespace
}  // namespace gyrocal
