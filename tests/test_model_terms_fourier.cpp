// The model terms summed in closed form from their Fourier series in the two joint angles
// (identify/model_terms.hpp, ModelTermsRoute::kExact) against the same model terms evaluated at every sample
// (ModelTermsRoute::kEverySample): on machines with large errors, each reduced model term is within the bound
// the series states (docs/calibration.md, "The model's side of each position"), and where the series' check
// fails the model terms are taken at every sample.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/model_terms.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace gyrocal {
namespace {

/// The default test at 200 Hz over two speeds (127 and 180 samples a revolution), noise-free.
Scenario two_speed_test(int revolutions) {
  Scenario s = default_scenario();
  s.test.sample_rate_hz = 200.0;
  s.test.revolutions = revolutions;
  s.test.rates_rad_s = {9.9, 7.0};
  s.noise = GyroNoise{};
  return s;
}

/// Large machine errors: a lever arm of 1 cm, runouts and wobbles of every joint to harmonic `highest`
/// (amplitudes 2e-4 falling by half a harmonic), position-platform errors, a counter rate mismatch (so that
/// the platform's heading drifts and the model terms depend on both joint angles).
void set_large_errors(Scenario& s, int highest) {
  CentrifugeErrors& e = s.errors;
  e.lever_arm_m = Eigen::Vector3d(0.01, -0.01, 0.01);
  const auto series = [&](double amplitude, double phase) {
    HarmonicSeries h;
    for (int n = 1; n <= highest; ++n)
      h.terms.push_back({n, amplitude / std::pow(2.0, n - 1), phase + 0.7 * n});
    return h;
  };
  e.main_runout_x_m = series(2e-4, 0.3);
  e.main_runout_y_m = series(1.5e-4, 0.7);
  e.main_wobble_x_rad = series(2e-4, 0.2);
  e.main_wobble_y_rad = series(1e-4, 1.9);
  e.counter_wobble_x_rad = series(1.5e-4, 2.2);
  e.counter_wobble_y_rad = series(2e-4, 1.2);
  e.position_wobble_x_rad = series(1e-4, 0.3);
  e.position_perpendicularity_x_rad = 2e-4;
  e.position_angle_error_rad = 3e-4;
  e.counter_rate_mismatch_rad_s = 2e-6;
}

Reduction reduce(const Scenario& s) {
  Reducer reducer(s.test, ReduceOptions{}, "large_errors.csv", s.centrifuge.rate_rad_s);
  SimulationOptions so;
  so.seed = 3;
  simulate(s, so, [&](const RecordSample& x) { reducer.push(x); });
  return reducer.finish();
}

/// Every reduced model term of `fourier` within the stated bound of `every`'s: the aliased and truncated part
/// of the series (twice the outer half band's sum, which majorises the tail of a decaying series) through
/// the operator's L1 norm (at most sqrt(samples x white-noise gain) by Cauchy-Schwarz), plus the two sums'
/// rounding (1e-13 of the model term's scale a sample, and 1e-15 of the joints' rates for a rate). Returns
/// the largest ratio of difference to bound.
double worst_ratio(const Reduction& r, const std::vector<PositionModelTerms>& fourier,
                   const std::vector<PositionModelTerms>& every,
                   const std::vector<DwellModelTermsRoute>& routes) {
  double worst = 0.0;
  for (std::size_t i = 0; i < r.positions.size(); ++i) {
    const ReducedPosition& p = r.positions[i];
    const Dwell& d = r.dwells[static_cast<std::size_t>(p.dwell)];
    const DwellModelTermsRoute& route = routes[static_cast<std::size_t>(p.dwell)];
    EXPECT_TRUE(route.fourier) << "position " << p.index;
    if (!route.fourier) return worst;
    std::vector<double> a = {fourier[i].omega_exact_deg_h, fourier[i].omega_nominal_deg_h,
                             fourier[i].omega_seed_deg_h};
    std::vector<double> b = {every[i].omega_exact_deg_h, every[i].omega_nominal_deg_h,
                             every[i].omega_seed_deg_h};
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
      a.push_back(fourier[i].regressors_exact[k]);
      b.push_back(every[i].regressors_exact[k]);
    }
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
      a.push_back(fourier[i].regressors_nominal[k]);
      b.push_back(every[i].regressors_nominal[k]);
    }
    a.push_back(fourier[i].omega_O_exact_deg_h);
    a.push_back(fourier[i].omega_S_exact_deg_h);
    b.push_back(every[i].omega_O_exact_deg_h);
    b.push_back(every[i].omega_S_exact_deg_h);
    const double l1 = std::sqrt(static_cast<double>(d.samples) *
                                route.operator_gain[static_cast<std::size_t>(p.gamma_slot)]);
    for (std::size_t c = 0; c < a.size(); ++c) {
      // The rates (columns 0-2 and the last two, deg/h) are differences of terms as large as the joints'
      // rates: each sample's rounding is ~1e-16 of those.
      const bool rate = c < 3 || c + 2 >= a.size();
      const double rates =
          (std::abs(d.main.rate_rad_s) + std::abs(d.counter.rate_rad_s)) * kRadPerSecToDegPerHour;
      const double rounding = 1e-13 * route.scale[c] + (rate ? 1e-15 * rates : 0.0);
      const double bound = l1 * (2.0 * route.outer_tail[c] + rounding) + 1e-300;
      if (std::abs(a[c] - b[c]) / bound > worst)
        std::printf("position %d, column %zu: |difference| %.3g, bound %.3g\n", p.index, c,
                    std::abs(a[c] - b[c]), bound);
      worst = std::max(worst, std::abs(a[c] - b[c]) / bound);
      EXPECT_LE(std::abs(a[c] - b[c]), bound)
          << "position " << p.index << ", column " << c << ": " << a[c] << " vs " << b[c];
    }
  }
  return worst;
}

TEST(FourierChannels, EqualTheEverySampleChannelsWithinTheirBoundOnAMachineWithLargeErrors) {
  Scenario s = two_speed_test(60);
  set_large_errors(s, 3);
  const Reduction r = reduce(s);
  std::vector<DwellModelTermsRoute> routes;
  const auto fourier = reduce_model_terms(r, s.model(), ReduceOptions{}, 0, ModelTermsRoute::kExact, &routes);
  const auto every = reduce_model_terms(r, s.model(), ReduceOptions{}, 0, ModelTermsRoute::kEverySample);
  ASSERT_EQ(routes.size(), r.dwells.size());
  for (std::size_t i = 0; i < routes.size(); ++i)
    std::printf("dwell %zu: %zu samples, %s, H = %d\n", i, r.dwells[i].samples,
                routes[i].fourier ? "closed forms" : "every sample", routes[i].harmonics);
  const double worst = worst_ratio(r, fourier, every, routes);
  std::printf("largest |fourier - every sample| / bound: %.3g (H = %d)\n", worst, routes.front().harmonics);
  // And the calibration from them is exact: every coefficient within 1e-7 of the truth (least squares, full
  // compensation), as with the every-sample model terms.
  CalibrationOptions o;
  o.method = Method::kLeastSquares;
  o.compensation = Compensation::kFull;
  const CalibrationResult c = identify(r, fourier, s.model(), o);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    ASSERT_TRUE(c.coefficients[k].identifiable) << kCoefficientNames[k];
    EXPECT_NEAR(c.coefficients[k].value, s.gyro.values[k], 1e-7) << kCoefficientNames[k];
  }
}

TEST(FourierChannels, TakeEverySampleWhereTheSeriesCheckFails) {
  // Wobbles and runouts to harmonic 9: H = 8 x 9 + 4 = 76 is beyond the closed forms' limit (64), so the
  // model terms are evaluated at every sample, and equal the every-sample route's exactly.
  Scenario s = two_speed_test(4);
  set_large_errors(s, 9);
  const Reduction r = reduce(s);
  std::vector<DwellModelTermsRoute> routes;
  const auto exact = reduce_model_terms(r, s.model(), ReduceOptions{}, 0, ModelTermsRoute::kExact, &routes);
  const auto every = reduce_model_terms(r, s.model(), ReduceOptions{}, 0, ModelTermsRoute::kEverySample);
  for (const DwellModelTermsRoute& route : routes) EXPECT_FALSE(route.fourier);
  for (std::size_t i = 0; i < exact.size(); ++i) {
    EXPECT_EQ(exact[i].omega_exact_deg_h, every[i].omega_exact_deg_h);
    EXPECT_EQ(exact[i].regressors_exact, every[i].regressors_exact);
  }
}

TEST(FourierChannels, AnAccelerometersDesignRowsEqualTheEverySampleOnesWithinTheirBound) {
  // The accelerometer's design row (its known part and its regressors, polynomials of degree <= 3 in the
  // specific force, g to g^3) on the same machine with large errors, static holds and two speeds, reduced to
  // the whole harmonic content as `calibrate` does: each reduced column by closed forms within the bound the
  // series states of the every-sample one, as the gyro's columns above.
  Scenario s = two_speed_test(60);
  s.sensor_kind = SensorKind::kAccelerometer;
  s.accelerometer = Accelerometer{};
  s.accelerometer.noise = AccelerometerNoise{};
  s.test.rates_rad_s = {0.0, 6.0, 12.0};
  s.centrifuge.rate_rad_s = 6.0;
  s.test.static_hold_s = 30.0;
  set_large_errors(s, 3);
  const ReduceOptions ro;
  Reducer reducer(reduction_plan(s.test, SensorKind::kAccelerometer, ro), ro, "large_errors.csv",
                  s.centrifuge.rate_rad_s);
  SimulationOptions so;
  so.seed = 3;
  simulate(s, so, [&](const RecordSample& x) { reducer.push(x); });
  const Reduction r = reducer.finish();
  std::vector<DwellModelTermsRoute> routes;
  const auto fourier =
      reduce_sensor_model_terms(r, s.model(), ro, s.channels().front(), 0, ModelTermsRoute::kExact, &routes);
  const auto every =
      reduce_sensor_model_terms(r, s.model(), ro, s.channels().front(), 0, ModelTermsRoute::kEverySample);
  ASSERT_EQ(routes.size(), r.dwells.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < r.positions.size(); ++i) {
    const ReducedPosition& p = r.positions[i];
    const Dwell& d = r.dwells[static_cast<std::size_t>(p.dwell)];
    const DwellModelTermsRoute& route = routes[static_cast<std::size_t>(p.dwell)];
    ASSERT_TRUE(route.fourier) << "position " << p.index << " (" << d.samples << " samples)";
    const DesignRow& a = fourier[i].sensor_exact;
    const DesignRow& b = every[i].sensor_exact;
    ASSERT_EQ(a.size, b.size);
    ASSERT_EQ(route.outer_tail.size(), a.size + 1);
    const double l1 = std::sqrt(static_cast<double>(d.samples) *
                                route.operator_gain[static_cast<std::size_t>(p.gamma_slot)]);
    for (std::size_t c = 0; c <= a.size; ++c) {
      const double x = c == 0 ? a.known : a.regressors[c - 1];
      const double y = c == 0 ? b.known : b.regressors[c - 1];
      // The aliased and truncated part (twice the outer band's sum) through the operator's L1 norm, plus the
      // two sums' rounding: the every-sample route adds the dwell's samples one by one, whose rounding grows
      // as (samples x 1.1e-16) of the column's scale (a static hold of 6000 like samples: 7e-13), at least
      // 1e-13 as for the gyro's columns above.
      const double rounding = std::max(1e-13, static_cast<double>(d.samples) * 1.1e-16);
      const double bound = l1 * (2.0 * route.outer_tail[c] + rounding * route.scale[c]) + 1e-300;
      worst = std::max(worst, std::abs(x - y) / bound);
      EXPECT_LE(std::abs(x - y), bound)
          << "position " << p.index << ", column " << c << ": " << x << " vs " << y;
    }
  }
  std::printf("largest |fourier - every sample| / bound: %.3g (H = %d)\n", worst, routes.back().harmonics);
  // The calibrations from the two: every coefficient the same to 1e-6 of its unit (ug, ug/g^n, urad), the
  // scale to 1e-12; and the noise-free truth recovered as an accelerometer's calibration must (1e-4 of each
  // unit, K1 1e-9).
  CalibrationOptions o;
  o.sensor = SensorKind::kAccelerometer;
  const CalibrationResult cf = identify(r, fourier, s.model(), o);
  const CalibrationResult ce = identify(r, every, s.model(), o);
  ASSERT_EQ(cf.coefficients.size(), s.accelerometer.coefficients.values.size());
  ASSERT_EQ(ce.coefficients.size(), cf.coefficients.size());
  for (std::size_t k = 0; k < cf.coefficients.size(); ++k) {
    const double x = cf.coefficients[k].value;
    EXPECT_NEAR(x, ce.coefficients[k].value, k == 1 ? 1e-12 : 1e-6) << cf.coefficients[k].name;
    EXPECT_NEAR(x, s.accelerometer.coefficients.values[k], k == 1 ? 1e-9 : 1e-4) << cf.coefficients[k].name;
  }
}

}  // namespace
}  // namespace gyrocal
