// The local gravity: an accelerometer's specific force is read in the local g, so the radius it measures is
// omega^2 R / g (docs/calibration.md, "The radius is measured against gravity"; docs/montecarlo.md,
// "Gravity"): [uncertainty] gravity_m_s2 is read and bounded, its Monte Carlo effect is the hand formula
// R0 u_g / g0 on the radius and none on K1, and a calibration that estimates the radius states the gravity
// it assumed.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gyrocal/analysis/montecarlo.hpp"
#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/model/machine_errors.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/simulated_pipeline.hpp"

namespace gyrocal {
namespace {

using testing::simulate_and_reduce;

/// A small accelerometer test that identifies all eleven coefficients: static holds, 6 and 12 rad/s, the four
/// quarter beta, the default truth and machine errors of [accelerometer] and [centrifuge.errors], few
/// revolutions at 50 Hz so that a record is simulated, reduced and identified in well under a second.
Scenario small_test() {
  Scenario s = default_scenario();
  s.sensor_kind = SensorKind::kAccelerometer;
  s.accelerometer = Accelerometer{};
  s.test.rates_rad_s = {0.0, 6.0, 12.0};
  s.centrifuge.rate_rad_s = 6.0;
  s.test.beta_rad = {0.0, kPi / 2, kPi, 3 * kPi / 2};
  s.test.revolutions = 8;
  s.test.sample_rate_hz = 50.0;
  s.test.settle_s = 2.0;
  s.test.static_hold_s = 2.0;
  return s;
}

CalibrationResult calibrate(const Scenario& config, const Reduction& reduction,
                            CalibrationOptions o = CalibrationOptions{}) {
  o.sensor = SensorKind::kAccelerometer;
  const CentrifugeModel model = config.model();
  return identify(reduction, reduce_sensor_model_terms(reduction, model, o.reduce, config.channels().front()),
                  model, o);
}

std::string all_warnings(const CalibrationResult& r) {
  std::string out;
  for (const std::string& w : r.warnings) out += w + "\n";
  return out;
}

TEST(AccelerometerGravity, UncertaintyKeyIsReadWrittenAndBounded) {
  Scenario s = small_test();
  s.gravity_uncertainty_m_s2 = 2.5e-5;
  const Scenario back = parse_scenario(scenario_to_toml(s), "round trip");
  EXPECT_EQ(back.gravity_uncertainty_m_s2, 2.5e-5);
  for (const char* bad : {"-1e-5", "2.0"}) {
    try {
      (void)parse_scenario(std::string("[uncertainty]\ngravity_m_s2 = ") + bad + "\n", "g.toml");
      ADD_FAILURE() << bad << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("uncertainty.gravity_m_s2"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("g.toml"), std::string::npos) << e.what();
    }
  }
}

TEST(AccelerometerGravity, ItsUncertaintyActsAsTheRadiusItMimics) {
  // The specific force is in the local g: the centripetal level is omega^2 R / g, so a true gravity g0 + u
  // reads as a radius R0 g0 / (g0 + u), a radius error of -R0 u / g0 to first order (1 um at 1 m per ppm;
  // tests/test_accelerometer_misfit.cpp checks that relation on a record). So in the Monte Carlo's linear
  // model the gravity's source of std u moves every coefficient as a radius source of std R0 u / g0 does,
  // with the opposite sign: an independent route (the machine's radius in the exact chain, not the site's g).
  Scenario s = small_test();
  const double g0 = s.site.gravity_m_s2, r0 = s.centrifuge.radius_m;
  s.gravity_uncertainty_m_s2 = 3e-6 * g0;  // 3 ppm
  s.uncertainty.radius_error_m = r0 * s.gravity_uncertainty_m_s2 / g0;
  MonteCarloOptions mo;
  mo.threads = 1;
  mo.calibration.sensor = SensorKind::kAccelerometer;
  const MonteCarloModel m = prepare_monte_carlo(s, mo);
  ASSERT_EQ(m.sources.size(), 2u);
  std::size_t gravity = 2, radius = 2;
  for (std::size_t k = 0; k < 2; ++k) (m.sources[k].gravity ? gravity : radius) = k;
  ASSERT_LT(gravity, 2u);
  ASSERT_LT(radius, 2u);
  EXPECT_EQ(m.sources[gravity].term.label(), "gravity");
  const std::size_t nc = m.columns();
  for (std::size_t i = 0; i < m.names.size(); ++i) {
    const double by_gravity = m.gain[i * nc + gravity], by_radius = m.gain[i * nc + radius];
    double noise = 0.0;
    for (std::size_t c = 2; c < nc; ++c) noise += m.gain[i * nc + c] * m.gain[i * nc + c];
    // Equal and opposite to 1 % of the larger, or both below 1e-3 of the noise's std.
    EXPECT_NEAR(by_gravity, -by_radius, 0.01 * std::abs(by_radius) + 1e-3 * std::sqrt(noise))
        << m.names[i] << ": gravity " << by_gravity << ", radius " << by_radius;
  }
}

TEST(AccelerometerGravity, EstimatingTheRadiusStatesTheGravityAssumed) {
  Scenario s = small_test();
  s.site.gravity_m_s2 = 9.8012;
  CalibrationOptions o;
  o.estimate = parse_machine_error_names({"radius_error"}, "test");
  const CalibrationResult r = calibrate(s, simulate_and_reduce(s, 3), o);
  const std::string w = all_warnings(r);
  EXPECT_NE(w.find("omega^2 R / g"), std::string::npos) << w;
  EXPECT_NE(w.find("g = 9.8012 m/s^2"), std::string::npos) << w;
  // 1 ppm of g is 1 ppm of R0: at the default R0 of 1 m, 1 um.
  EXPECT_NE(w.find(fmt::format("{:.3g} um at R0 = {:g} m", s.centrifuge.radius_m, s.centrifuge.radius_m)),
            std::string::npos)
      << w;
  const CalibrationResult plain = calibrate(s, simulate_and_reduce(s, 3));
  EXPECT_EQ(all_warnings(plain).find("omega^2 R / g"), std::string::npos);
}

}  // namespace
}  // namespace gyrocal
