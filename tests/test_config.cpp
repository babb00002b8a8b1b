// The configuration file: round trips, units, defaults, and every kind of bad value refused with its key
// and line (docs/contract.md, "Configuration (TOML)").
#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/plan/timeline.hpp"
#include "gyrocal/reduce/feasibility.hpp"
#include "support/cli_run.hpp"
#include "support/simulated_pipeline.hpp"

namespace gyrocal {
namespace {

// Independent of the library's constants: 1 rad = 180*3600/pi arcsec.
constexpr double kArcsecPerRad = 206264.80624709636;

// ---- exact comparison of every field -------------------------------------------------------------------

void expect_same(double a, double b, const std::string& what) {
  EXPECT_EQ(std::bit_cast<std::uint64_t>(a), std::bit_cast<std::uint64_t>(b))
      << what << ": " << a << " != " << b;
}

void expect_same(const std::vector<double>& a, const std::vector<double>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) expect_same(a[i], b[i], what + "[" + std::to_string(i) + "]");
}

void expect_same(const HarmonicSeries& a, const HarmonicSeries& b, const std::string& what) {
  ASSERT_EQ(a.terms.size(), b.terms.size()) << what;
  for (std::size_t i = 0; i < a.terms.size(); ++i) {
    const std::string term = what + "[" + std::to_string(i) + "]";
    EXPECT_EQ(a.terms[i].harmonic, b.terms[i].harmonic) << term;
    expect_same(a.terms[i].amplitude, b.terms[i].amplitude, term + ".amplitude");
    expect_same(a.terms[i].phase_rad, b.terms[i].phase_rad, term + ".phase");
  }
}

void expect_same(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const std::string& what) {
  for (int i = 0; i < 3; ++i) expect_same(a[i], b[i], what + "[" + std::to_string(i) + "]");
}

void expect_same(const CentrifugeErrors& a, const CentrifugeErrors& b, const std::string& w) {
  expect_same(a.base_tilt_x_rad, b.base_tilt_x_rad, w + "base_tilt_x");
  expect_same(a.base_tilt_y_rad, b.base_tilt_y_rad, w + "base_tilt_y");
  expect_same(a.main_perpendicularity_x_rad, b.main_perpendicularity_x_rad, w + "main_perpendicularity_x");
  expect_same(a.main_perpendicularity_y_rad, b.main_perpendicularity_y_rad, w + "main_perpendicularity_y");
  expect_same(a.main_wobble_x_rad, b.main_wobble_x_rad, w + "main_wobble_x");
  expect_same(a.main_wobble_y_rad, b.main_wobble_y_rad, w + "main_wobble_y");
  expect_same(a.main_runout_x_m, b.main_runout_x_m, w + "main_runout_x");
  expect_same(a.main_runout_y_m, b.main_runout_y_m, w + "main_runout_y");
  expect_same(a.radius_error_m, b.radius_error_m, w + "radius_error");
  expect_same(a.radius_stretch_m_per_rad2_s2, b.radius_stretch_m_per_rad2_s2, w + "radius_stretch");
  expect_same(a.counter_perpendicularity_x_rad, b.counter_perpendicularity_x_rad,
              w + "counter_perpendicularity_x");
  expect_same(a.counter_perpendicularity_y_rad, b.counter_perpendicularity_y_rad,
              w + "counter_perpendicularity_y");
  expect_same(a.counter_wobble_x_rad, b.counter_wobble_x_rad, w + "counter_wobble_x");
  expect_same(a.counter_wobble_y_rad, b.counter_wobble_y_rad, w + "counter_wobble_y");
  expect_same(a.counter_rate_mismatch_rad_s, b.counter_rate_mismatch_rad_s, w + "counter_rate_mismatch");
  expect_same(a.position_perpendicularity_x_rad, b.position_perpendicularity_x_rad, w + "position_perp_x");
  expect_same(a.position_perpendicularity_z_rad, b.position_perpendicularity_z_rad, w + "position_perp_z");
  expect_same(a.position_wobble_x_rad, b.position_wobble_x_rad, w + "position_wobble_x");
  expect_same(a.position_wobble_z_rad, b.position_wobble_z_rad, w + "position_wobble_z");
  expect_same(a.position_angle_error_rad, b.position_angle_error_rad, w + "position_angle_error");
  expect_same(a.mount_misalignment_rad, b.mount_misalignment_rad, w + "mount_misalignment");
  expect_same(a.lever_arm_m, b.lever_arm_m, w + "lever_arm");
}

/// Every ReduceOptions field, listed here by hand (not from the configuration's key table).
void expect_same(const ReduceOptions& a, const ReduceOptions& b) {
  EXPECT_EQ(a.method, b.method) << "reduce method";
  EXPECT_EQ(a.harmonic_order, b.harmonic_order) << "reduce.harmonic_order";
  EXPECT_EQ(a.linear_drift, b.linear_drift) << "reduce.linear_drift";
  expect_same(a.window_deg, b.window_deg, "reduce.window_deg");
  expect_same(a.window_s, b.window_s, "reduce.window_s");
  expect_same(a.angle_tolerance_deg, b.angle_tolerance_deg, "reduce.angle_tolerance_deg");
  expect_same(a.beta_tolerance_deg, b.beta_tolerance_deg, "reduce.beta_tolerance_deg");
  expect_same(a.rate_tolerance, b.rate_tolerance, "reduce.rate_tolerance");
  expect_same(a.rate_steadiness, b.rate_steadiness, "reduce.rate_steadiness");
  expect_same(a.static_rate_tolerance_rad_s, b.static_rate_tolerance_rad_s, "reduce.static_rate_tolerance");
  expect_same(a.wander_warning_deg, b.wander_warning_deg, "reduce.wander_warning_deg");
  expect_same(a.gap_intervals, b.gap_intervals, "reduce.gap_intervals");
  EXPECT_EQ(a.encoder_glitch_rows, b.encoder_glitch_rows) << "reduce.encoder_glitch_rows";
  expect_same(a.leave_guard_s, b.leave_guard_s, "reduce.leave_guard_s");
  EXPECT_EQ(a.max_stretches_per_dwell, b.max_stretches_per_dwell) << "reduce.max_stretches_per_dwell";
  EXPECT_EQ(a.static_batches, b.static_batches) << "reduce.static_batches";
  EXPECT_EQ(a.model_samples_per_revolution, b.model_samples_per_revolution)
      << "reduce.model_samples_per_revolution";
  expect_same(a.outlier_threshold, b.outlier_threshold, "reduce.outlier_threshold");
  EXPECT_EQ(a.outlier_block_samples, b.outlier_block_samples) << "reduce.outlier_block_samples";
}

/// Every ReduceOptions field away from its default, within its range.
ReduceOptions changed_reduce_options() {
  ReduceOptions o;
  o.method = ReduceOptions::Method::kWindowMean;
  o.harmonic_order = 5;
  o.linear_drift = false;
  o.window_deg = 7.5;
  o.window_s = 0.75;
  o.angle_tolerance_deg = 0.35;
  o.beta_tolerance_deg = 0.15;
  o.rate_tolerance = 5e-3;
  o.rate_steadiness = 2.5e-3;
  o.static_rate_tolerance_rad_s = 0.02;
  o.wander_warning_deg = 0.03;
  o.gap_intervals = 2.5;
  o.encoder_glitch_rows = 5;
  o.leave_guard_s = 0.4;
  o.max_stretches_per_dwell = 100;
  o.static_batches = 10;
  o.model_samples_per_revolution = 64;
  o.outlier_threshold = 8.0;
  o.outlier_block_samples = 256;
  return o;
}

void expect_same(const Scenario& a, const Scenario& b) {
  expect_same(a.site.latitude_rad, b.site.latitude_rad, "site.latitude");
  expect_same(a.site.gravity_m_s2, b.site.gravity_m_s2, "site.gravity");
  expect_same(a.site.earth_rate_rad_s, b.site.earth_rate_rad_s, "site.earth_rate");
  expect_same(a.centrifuge.radius_m, b.centrifuge.radius_m, "centrifuge.radius");
  expect_same(a.centrifuge.rate_rad_s, b.centrifuge.rate_rad_s, "centrifuge.rate");
  expect_same(a.centrifuge.heading_rad, b.centrifuge.heading_rad, "centrifuge.heading");
  expect_same(a.centrifuge.initial_main_angle_rad, b.centrifuge.initial_main_angle_rad, "centrifuge.theta0");
  expect_same(a.errors, b.errors, "errors.");
  for (std::size_t i = 0; i < kNumGyroCoefficients; ++i) {
    expect_same(a.gyro.values[i], b.gyro.values[i], "gyro." + std::string(kCoefficientNames[i]));
  }
  expect_same(a.noise.angle_random_walk_deg_rt_h, b.noise.angle_random_walk_deg_rt_h, "noise.arw");
  expect_same(a.noise.bias_instability_deg_h, b.noise.bias_instability_deg_h, "noise.bias_instability");
  expect_same(a.noise.rate_random_walk_deg_h_rt_h, b.noise.rate_random_walk_deg_h_rt_h, "noise.rrw");
  expect_same(a.noise.quantization_deg_h, b.noise.quantization_deg_h, "noise.quantization");
  expect_same(a.noise.output_lag_s, b.noise.output_lag_s, "noise.output_lag");
  expect_same(a.test.sample_rate_hz, b.test.sample_rate_hz, "test.sample_rate");
  EXPECT_EQ(a.test.revolutions, b.test.revolutions);
  expect_same(a.test.settle_s, b.test.settle_s, "test.settle");
  expect_same(a.test.beta_rad, b.test.beta_rad, "test.beta");
  expect_same(a.test.gamma_rad, b.test.gamma_rad, "test.gamma");
  expect_same(a.test.rates_rad_s, b.test.rates_rad_s, "test.rates");
  expect_same(a.test.static_hold_s, b.test.static_hold_s, "test.static_hold_s");
  EXPECT_EQ(a.test.seed, b.test.seed);
  expect_same(a.uncertainty, b.uncertainty, "uncertainty.");
  expect_same(a.reduce, b.reduce);
}

Scenario round_trip(const Scenario& s) {
  return parse_scenario(scenario_to_toml(s), "round-trip.toml");
}

/// A scenario with every field away from its default (angles given in the file's units).
Scenario changed_scenario() {
  Scenario s;
  s.site = {-33.5 * kDegToRad, 9.79, 7.3e-5};
  s.centrifuge = {2.25, -12.5, 15.0 * kDegToRad, -30.0 * kDegToRad};
  CentrifugeErrors& e = s.errors;
  e.base_tilt_x_rad = 1.5 * kArcsecToRad;
  e.base_tilt_y_rad = -2.5 * kArcsecToRad;
  e.main_perpendicularity_x_rad = 0.7 * kArcsecToRad;
  e.main_perpendicularity_y_rad = -0.3 * kArcsecToRad;
  e.main_wobble_x_rad.terms = {{1, 0.25 * kArcsecToRad, 10.0 * kDegToRad},
                               {3, 0.1 * kArcsecToRad, -45.0 * kDegToRad}};
  e.main_wobble_y_rad.terms = {{2, 0.4 * kArcsecToRad, 33.3 * kDegToRad}};
  e.main_runout_x_m.terms = {{1, 2e-6, 5.0 * kDegToRad}};
  e.main_runout_y_m.terms = {{4, 1.25e-7, 0.0}};
  e.radius_error_m = 1e-4;
  e.radius_stretch_m_per_rad2_s2 = 3e-8;
  e.counter_perpendicularity_x_rad = 4.1 * kArcsecToRad;
  e.counter_perpendicularity_y_rad = 1.1 * kArcsecToRad;
  e.counter_wobble_x_rad.terms = {{5, 0.9 * kArcsecToRad, 123.0 * kDegToRad}};
  e.counter_wobble_y_rad.terms = {};
  e.counter_rate_mismatch_rad_s = -3.3e-6;
  e.position_perpendicularity_x_rad = 0.2 * kArcsecToRad;
  e.position_perpendicularity_z_rad = -0.6 * kArcsecToRad;
  e.position_wobble_x_rad.terms = {{1, 0.05 * kArcsecToRad, 1.0 * kDegToRad}};
  e.position_wobble_z_rad.terms = {{2, 0.07 * kArcsecToRad, 2.0 * kDegToRad}};
  e.position_angle_error_rad = 3.7 * kArcsecToRad;
  e.mount_misalignment_rad = Eigen::Vector3d(10.0, -20.0, 30.5) * kArcsecToRad;
  e.lever_arm_m = Eigen::Vector3d(0.01, -0.02, 0.003);
  for (std::size_t i = 0; i < kNumGyroCoefficients; ++i)
    s.gyro.values[i] = 0.1 * static_cast<double>(i) - 0.37;
  s.noise = {0.01, 0.02, 0.03, 0.004, 0.005};
  s.test.sample_rate_hz = 1000.0;
  s.test.revolutions = 17;
  s.test.settle_s = 0.5;
  s.test.beta_rad = {45.0 * kDegToRad, 135.0 * kDegToRad};
  s.test.gamma_rad = {10.0 * kDegToRad, 20.0 * kDegToRad, 30.0 * kDegToRad};
  // The centrifuge's rate (-12.5) is one of the test's, not its first: written beside them.
  s.test.rates_rad_s = {0.0, 5.0, -12.5};
  s.test.seed = 123456789012345ULL;
  s.test.static_hold_s = 42.5;
  CentrifugeErrors& u = s.uncertainty;
  u.base_tilt_x_rad = 0.5 * kArcsecToRad;
  u.counter_perpendicularity_x_rad = 0.3 * kArcsecToRad;
  u.counter_wobble_x_rad.terms = {{2, 0.2 * kArcsecToRad, 20.0 * kDegToRad}};
  u.main_runout_x_m.terms = {{1, 1e-7, 0.0}};
  u.counter_rate_mismatch_rad_s = 1e-7;
  u.mount_misalignment_rad = Eigen::Vector3d(1.0, 2.0, 3.0) * kArcsecToRad;
  u.lever_arm_m = Eigen::Vector3d(1e-3, 2e-3, 3e-3);
  s.reduce = changed_reduce_options();
  return s;
}

// ---- round trips and defaults ----------------------------------------------------------------------------

TEST(Config, DefaultScenarioRoundTripsExactly) {
  expect_same(round_trip(default_scenario()), default_scenario());
}

TEST(Config, ChangedScenarioRoundTripsExactly) {
  const Scenario s = changed_scenario();
  expect_same(round_trip(s), s);
  // The comparison itself must see the changes.
  EXPECT_NE(std::bit_cast<std::uint64_t>(s.errors.lever_arm_m.z()),
            std::bit_cast<std::uint64_t>(default_scenario().errors.lever_arm_m.z()));
}

TEST(Config, RandomValuesRoundTripBitForBit) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-12, 6);
  const auto random_value = [&] { return unit(rng) * std::pow(10.0, exponent(rng)); };
  // Below 10^top: a key with a physical range (core/limits.hpp: 1 m, 2e5 arcsec, 100 m/s^2).
  const auto bounded_value = [&](int top) {
    return unit(rng) * std::pow(10.0, std::min(exponent(rng), top));
  };
  for (int trial = 0; trial < 300; ++trial) {
    Scenario s = default_scenario();
    s.site.latitude_rad = 90.0 * unit(rng) * kDegToRad;
    s.site.gravity_m_s2 = std::abs(bounded_value(1)) + 1e-3;
    s.centrifuge.rate_rad_s = random_value();
    s.test.rates_rad_s = {s.centrifuge.rate_rad_s};  // one rate, one place (written once, in [test])
    s.test.static_hold_s = std::abs(random_value());
    s.centrifuge.heading_rad = random_value() * kDegToRad;
    s.errors.counter_perpendicularity_x_rad = bounded_value(5) * kArcsecToRad;
    s.errors.lever_arm_m = Eigen::Vector3d(bounded_value(0), bounded_value(0), bounded_value(0));
    s.errors.counter_wobble_x_rad.terms = {
        {3, std::abs(bounded_value(5)) * kArcsecToRad, random_value() * kDegToRad}};
    s.gyro.values[0] = random_value();
    s.test.gamma_rad = {random_value() * kDegToRad};
    s.uncertainty.position_angle_error_rad = std::abs(bounded_value(5)) * kArcsecToRad;
    expect_same(round_trip(s), s);
    if (HasFailure()) break;
  }
}

TEST(Config, WrittenFileIsReadableAndUsesTheInterfaceNames) {
  const std::string text = scenario_to_toml(default_scenario());
  // Shortest decimal forms: 3 arcsec is written 3.0, not 2.9999999999999996.
  for (const char* line :
       {"latitude_deg = 39.13 ", "counter_perpendicularity_x_arcsec = 3.0 ",
        "counter_perpendicularity_y_arcsec = -2.0 ", "beta_deg = [0.0, 180.0, 90.0, 270.0] ",
        "counter_wobble_x = [ { harmonic = 2, amplitude_arcsec = 1.0, phase_deg = 20.0 } ]", "[uncertainty]",
        "[gyro.noise]", "seed = 1 "}) {
    EXPECT_NE(text.find(line), std::string::npos) << line << "\n" << text;
  }
  // Every key line carries a comment.
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (!line.starts_with("#") && line.find(" = ") != std::string::npos) {
      EXPECT_NE(line.find("  # "), std::string::npos) << line;
    }
  }
}

/// k/100 as a TOML float: "-127.96", "0.07", "3.0".
std::string hundredths_text(int k) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, k / 100.0);
  std::string text(buffer, result.ptr);
  if (text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}

TEST(Config, AnglesAreWrittenBackAsTyped) {
  // Dividing by the unit factor alone gives e.g. 127.96000000000001 deg for 127.96 deg (about one value in
  // ten with two decimals): the writer must find the shortest number that reads back to the same radians.
  for (int k = -20000; k <= 20000; k += 13) {
    const std::string value = hundredths_text(k);
    for (const char* key : {"heading_deg", "counter_perpendicularity_x_arcsec"}) {
      const std::string section =
          std::string(key) == "heading_deg" ? "[centrifuge]\n" : "[centrifuge.errors]\n";
      const std::string line = std::string(key) + " = " + value;
      const std::string text = scenario_to_toml(parse_scenario(section + line + "\n", "typed.toml"));
      ASSERT_NE(text.find(line + " "), std::string::npos) << line;
    }
  }
}

TEST(Config, EmptyTextGivesTheDefaultScenario) {
  expect_same(parse_scenario("", "empty.toml"), default_scenario());
  expect_same(parse_scenario("# only a comment\n\n", "empty.toml"), default_scenario());
}

TEST(Config, UnitsAreConvertedToSi) {
  const Scenario s = parse_scenario(
      "[site]\nlatitude_deg = 45\n"
      "[centrifuge]\nradius_m = 2\nheading_deg = 90.0\n"
      "[centrifuge.errors]\ncounter_perpendicularity_x_arcsec = 3.0\n"
      "main_wobble_y = [ { harmonic = 3, amplitude_arcsec = 2.0, phase_deg = 180.0 } ]\n"
      "main_runout_x = [ { harmonic = 1, amplitude_m = 1e-6 } ]\n"
      "mount_misalignment_arcsec = [1.0, -2.0, 0]\n"
      "[test]\nbeta_deg = [30.0]\n",
      "units.toml");
  EXPECT_DOUBLE_EQ(s.site.latitude_rad, std::numbers::pi / 4);
  EXPECT_EQ(s.centrifuge.radius_m, 2.0);  // an integer where a float is expected
  EXPECT_DOUBLE_EQ(s.centrifuge.heading_rad, std::numbers::pi / 2);
  EXPECT_DOUBLE_EQ(s.errors.counter_perpendicularity_x_rad, 3.0 / kArcsecPerRad);
  ASSERT_EQ(s.errors.main_wobble_y_rad.terms.size(), 1u);
  EXPECT_EQ(s.errors.main_wobble_y_rad.terms[0].harmonic, 3);
  EXPECT_DOUBLE_EQ(s.errors.main_wobble_y_rad.terms[0].amplitude, 2.0 / kArcsecPerRad);
  EXPECT_DOUBLE_EQ(s.errors.main_wobble_y_rad.terms[0].phase_rad, std::numbers::pi);
  ASSERT_EQ(s.errors.main_runout_x_m.terms.size(), 1u);
  EXPECT_EQ(s.errors.main_runout_x_m.terms[0].amplitude, 1e-6);  // metres stay metres
  EXPECT_EQ(s.errors.main_runout_x_m.terms[0].phase_rad, 0.0);
  EXPECT_DOUBLE_EQ(s.errors.mount_misalignment_rad.y(), -2.0 / kArcsecPerRad);
  EXPECT_DOUBLE_EQ(s.test.beta_rad.at(0), std::numbers::pi / 6);
  // Keys not given keep their defaults.
  EXPECT_EQ(s.errors.counter_perpendicularity_y_rad,
            default_scenario().errors.counter_perpendicularity_y_rad);
}

TEST(Config, TestRatesDefaultToTheCentrifugeRate) {
  const Scenario alone = parse_scenario("[centrifuge]\nrate_rad_s = 5.5\n", "rate.toml");
  EXPECT_EQ(alone.test.rates_rad_s, std::vector<double>{5.5});
  const Scenario both =
      parse_scenario("[centrifuge]\nrate_rad_s = 3.0\n[test]\nrates_rad_s = [0, 3.0]\n", "rate.toml");
  EXPECT_EQ(both.centrifuge.rate_rad_s, 3.0);
  EXPECT_EQ(both.test.rates_rad_s, (std::vector<double>{0.0, 3.0}));
}

TEST(Config, UncertaintySectionIsReadAndDefaultsToZero) {
  const Scenario none = parse_scenario("", "u.toml");
  EXPECT_EQ(none.uncertainty.counter_perpendicularity_x_rad, 0.0);
  EXPECT_TRUE(none.uncertainty.counter_wobble_x_rad.empty());
  const Scenario s = parse_scenario(
      "[uncertainty]\ncounter_perpendicularity_x_arcsec = 0.5\n"
      "counter_wobble_y = [ { harmonic = 2, amplitude_arcsec = 0.25, phase_deg = 70.0 } ]\n",
      "u.toml");
  EXPECT_DOUBLE_EQ(s.uncertainty.counter_perpendicularity_x_rad, 0.5 / kArcsecPerRad);
  ASSERT_EQ(s.uncertainty.counter_wobble_y_rad.terms.size(), 1u);
  EXPECT_DOUBLE_EQ(s.uncertainty.counter_wobble_y_rad.terms[0].amplitude, 0.25 / kArcsecPerRad);
  // The nominal errors are untouched by their uncertainties.
  expect_same(s.errors, default_scenario().errors, "errors.");
}

// ---- bad values ------------------------------------------------------------------------------------------

/// The error message parse_scenario gives for text (a test failure if it accepts the text).
std::string error_of(const std::string& text) {
  try {
    parse_scenario(text, "bad.toml");
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted:\n" << text;
  return "";
}

/// Checks that text is refused with a message naming the file, line and key path.
void expect_refused(const std::string& text, int line, const std::string& key, const std::string& why) {
  const std::string message = error_of(text);
  EXPECT_NE(message.find("bad.toml, line " + std::to_string(line) + ":"), std::string::npos) << message;
  EXPECT_NE(message.find(key), std::string::npos) << message;
  EXPECT_NE(message.find(why), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(ConfigErrors, UnknownKeys) {
  expect_refused("[site]\nlatitude_deg = 1.0\n\nfoo = 1\n", 4, "site.foo", "unknown key");
  expect_refused("bar = 1\n", 1, "unknown key bar", "expected one of site, centrifuge");
  expect_refused("[centrifuge.errors]\nbase_tilt_x = 1.0\n", 2, "centrifuge.errors.base_tilt_x",
                 "unknown key");
  expect_refused("[gyro.noise]\nangle_random_walk = 0.1\n", 2, "gyro.noise.angle_random_walk", "unknown key");
  // A wobble's amplitude is in arcsec, a runout's in metres.
  expect_refused("[centrifuge.errors]\n\ncounter_wobble_x = [ { harmonic = 2, amplitude_m = 1.0 } ]\n", 3,
                 "centrifuge.errors.counter_wobble_x[0].amplitude_m", "unknown key");
  expect_refused("[uncertainty]\nradius_m = 1.0\n", 2, "uncertainty.radius_m", "unknown key");
}

TEST(ConfigErrors, WrongTypes) {
  expect_refused("[centrifuge]\nradius_m = \"one\"\n", 2, "centrifuge.radius_m",
                 "must be a number, not a string");
  expect_refused("site = 3\n", 1, "site", "must be a table");
  expect_refused("[test]\nbeta_deg = 90.0\n", 2, "test.beta_deg", "must be an array");
  expect_refused("[test]\nbeta_deg = [0.0, true]\n", 2, "test.beta_deg[1]",
                 "must be a number, not a boolean");
  expect_refused("[centrifuge.errors]\nmain_wobble_x = [ 1.0 ]\n", 2, "centrifuge.errors.main_wobble_x[0]",
                 "must be a table");
  expect_refused("[test]\nrevolutions = 10.0\n", 2, "test.revolutions", "must be an integer");
}

TEST(ConfigErrors, NonFiniteValues) {
  expect_refused("[site]\n\nlatitude_deg = nan\n", 3, "site.latitude_deg", "finite");
  expect_refused("[gyro]\ndF = inf\n", 2, "gyro.dF", "finite");
  expect_refused("[centrifuge.errors]\ncounter_rate_mismatch_rad_s = -inf\n", 2,
                 "centrifuge.errors.counter_rate_mismatch_rad_s", "finite");
  expect_refused("[test]\nrates_rad_s = [1.0, nan]\n", 2, "test.rates_rad_s[1]", "finite");
}

TEST(ConfigErrors, OutOfRange) {
  expect_refused("[centrifuge]\nradius_m = -1.0\n", 2, "centrifuge.radius_m", "must be > 0 and <= 1000");
  expect_refused("[centrifuge]\nradius_m = 0\n", 2, "centrifuge.radius_m", "must be > 0");
  expect_refused("[site]\nlatitude_deg = 91\n", 2, "site.latitude_deg", "between -90 and 90");
  expect_refused("[site]\ngravity_m_s2 = 0.0\n", 2, "site.gravity_m_s2", "> 0");
  expect_refused("[site]\nearth_rate_rad_s = -1e-5\n", 2, "site.earth_rate_rad_s", "between 0 and 1");
  expect_refused("[gyro.noise]\nquantization_deg_h = -0.1\n", 2, "gyro.noise.quantization_deg_h",
                 "between 0 and 1e+07");
  expect_refused("[test]\nsample_rate_hz = 0\n", 2, "test.sample_rate_hz", "> 0");
  expect_refused("[test]\nrevolutions = 0\n", 2, "test.revolutions", "integer >= 1");
  expect_refused("[test]\nsettle_s = -2.0\n", 2, "test.settle_s", ">= 0");
  expect_refused("[test]\nseed = -1\n", 2, "test.seed", "integer >= 0");
  expect_refused("[test]\ngamma_deg = []\n", 2, "test.gamma_deg", "must not be empty");
  expect_refused("[uncertainty]\nbase_tilt_x_arcsec = -0.5\n", 2, "uncertainty.base_tilt_x_arcsec",
                 "between 0 and 2e+05");
}

TEST(ConfigErrors, BadHarmonics) {
  const std::string head =
      "[centrifuge.errors]\nmain_wobble_y = [\n  { harmonic = 1, amplitude_arcsec = 1.0 },\n";
  expect_refused(head + "  { harmonic = 0, amplitude_arcsec = 1.0 },\n]\n", 4,
                 "centrifuge.errors.main_wobble_y[1].harmonic", "integer >= 1, not 0");
  expect_refused(head + "  { harmonic = 1.5 },\n]\n", 4, "centrifuge.errors.main_wobble_y[1].harmonic",
                 "must be an integer");
  expect_refused(head + "  { amplitude_arcsec = -1.0 },\n]\n", 4,
                 "centrifuge.errors.main_wobble_y[1].amplitude_arcsec", "between 0 and 2e+05");
}

TEST(ConfigErrors, WrongArrayLength) {
  expect_refused("[centrifuge.errors]\nmount_misalignment_arcsec = [1.0, 2.0]\n", 2,
                 "centrifuge.errors.mount_misalignment_arcsec", "exactly 3 numbers, not 2");
  expect_refused("[centrifuge.errors]\nlever_arm_m = [0.0, 0.0, 0.0, 0.0]\n", 2,
                 "centrifuge.errors.lever_arm_m", "exactly 3 numbers, not 4");
}

TEST(ConfigErrors, SyntaxError) {
  const std::string message = error_of("[site]\nlatitude_deg = 1.0\nlatitude_deg = = 3\n");
  EXPECT_NE(message.find("bad.toml, line 3:"), std::string::npos) << message;
  EXPECT_NE(message.find("TOML syntax error"), std::string::npos) << message;
}

// ---- [reduce] and [calibration] reduction ----------------------------------------------------------------

TEST(ConfigReduce, EveryKeyIsReadInItsOwnUnit) {
  // Written by hand, so that the reader is checked independently of the writer.
  const Scenario s = parse_scenario(R"([calibration]
reduction = "window"
[reduce]
harmonic_order = 5
linear_drift = false
window_deg = 7.5
window_s = 0.75
angle_tolerance_deg = 0.35
beta_tolerance_deg = 0.15
rate_tolerance = 5e-3
rate_steadiness = 2.5e-3
static_rate_tolerance_rad_s = 0.02
wander_warning_deg = 0.03
gap_intervals = 2.5
encoder_glitch_rows = 5
leave_guard_s = 0.4
max_stretches_per_dwell = 100
static_batches = 10
model_samples_per_revolution = 64
outlier_threshold = 8
outlier_block_samples = 256
)",
                                    "reduce.toml");
  expect_same(s.reduce, changed_reduce_options());
  // The comparison sees every field: each differs from its default.
  const ReduceOptions d;
  const ReduceOptions c = changed_reduce_options();
  EXPECT_NE(c.method, d.method);
  for (const auto& [changed, original] : {std::pair{c.window_deg, d.window_deg},
                                          {c.window_s, d.window_s},
                                          {c.angle_tolerance_deg, d.angle_tolerance_deg},
                                          {c.beta_tolerance_deg, d.beta_tolerance_deg},
                                          {c.rate_tolerance, d.rate_tolerance},
                                          {c.rate_steadiness, d.rate_steadiness},
                                          {c.static_rate_tolerance_rad_s, d.static_rate_tolerance_rad_s},
                                          {c.wander_warning_deg, d.wander_warning_deg},
                                          {c.gap_intervals, d.gap_intervals},
                                          {c.leave_guard_s, d.leave_guard_s},
                                          {c.outlier_threshold, d.outlier_threshold}})
    EXPECT_NE(changed, original);
  for (const auto& [changed, original] : {std::pair{c.harmonic_order, d.harmonic_order},
                                          {c.encoder_glitch_rows, d.encoder_glitch_rows},
                                          {c.max_stretches_per_dwell, d.max_stretches_per_dwell},
                                          {c.static_batches, d.static_batches},
                                          {c.model_samples_per_revolution, d.model_samples_per_revolution},
                                          {c.outlier_block_samples, d.outlier_block_samples}})
    EXPECT_NE(changed, original);
  EXPECT_NE(c.linear_drift, d.linear_drift);
  // Without the section every option keeps ReduceOptions' default.
  expect_same(parse_scenario("", "empty.toml").reduce, ReduceOptions{});
  EXPECT_EQ(parse_scenario("[calibration]\nreduction = \"harmonic\"\n", "h.toml").reduce.method,
            ReduceOptions::Method::kHarmonicFit);
}

TEST(ConfigReduce, InitWritesEveryKeyWithItsUnitDefaultAndReasonAndReadsBack) {
  // init's text (the default scenario) reads back to the default options, and a changed scenario's text to
  // the changed ones (every key written, none lost).
  const std::string text = scenario_to_toml(default_scenario());
  expect_same(parse_scenario(text, "init.toml").reduce, ReduceOptions{});
  Scenario s = default_scenario();
  s.reduce = changed_reduce_options();
  expect_same(round_trip(s).reduce, s.reduce);
  // Each key on its own line in [reduce], its comment giving the unit and the default with its reason.
  const std::size_t section = text.find("\n[reduce]\n");
  ASSERT_NE(section, std::string::npos) << text;
  for (const char* line :
       {"harmonic_order = 3 ", "linear_drift = true ", "window_deg = 10.0 ", "window_s = 0.5 ",
        "angle_tolerance_deg = 0.5 ", "beta_tolerance_deg = 0.2 ", "rate_tolerance = 0.002 ",
        "rate_steadiness = 0.001 ", "static_rate_tolerance_rad_s = 0.01 ", "wander_warning_deg = 0.01 ",
        "gap_intervals = 1.5 ", "encoder_glitch_rows = 3 ", "leave_guard_s = 0.25 ",
        "max_stretches_per_dwell = 4096 ", "static_batches = 16 ", "model_samples_per_revolution = 0 ",
        "outlier_threshold = 6.0 ", "outlier_block_samples = 128 "}) {
    const std::size_t at = text.find(std::string("\n") + line, section);
    ASSERT_NE(at, std::string::npos) << line << "\n" << text;
    const std::string key_line = text.substr(at + 1, text.find('\n', at + 1) - at - 1);
    EXPECT_NE(key_line.find("# "), std::string::npos) << key_line;
    EXPECT_NE(key_line.find("; default "), std::string::npos) << key_line;
  }
  EXPECT_NE(text.find("rate_tolerance = 0.002"), std::string::npos);
  EXPECT_NE(text.find("# relative; default 0.002: a steady rate matches a planned rate"), std::string::npos)
      << text;
  EXPECT_NE(text.find("reduction = \"harmonic\" "), std::string::npos) << text;
}

TEST(ConfigReduce, EachOutOfRangeValueIsRefusedNamingItsKey) {
  // One value beyond each key's range (ReduceOptions::IsValid), each at line 3.
  const std::pair<const char*, const char*> bad[] = {
      {"harmonic_order = 13", "between 0 and 12"},
      {"window_deg = 90.0", "(0, 90)"},
      {"window_s = 0.0", "(0, 60]"},
      {"angle_tolerance_deg = -0.5", "(0, 90)"},
      {"beta_tolerance_deg = 0.0", "positive"},
      {"rate_tolerance = 0.5", "(0, 0.5)"},
      {"rate_steadiness = 0.0", "(0, 0.5)"},
      {"static_rate_tolerance_rad_s = -0.01", "positive"},
      {"wander_warning_deg = 0.0", "positive"},
      {"gap_intervals = 1.0", "above 1"},
      {"encoder_glitch_rows = -1", "between 0 and 1000"},
      {"leave_guard_s = 61", "[0, 60]"},
      {"max_stretches_per_dwell = 0", "at least 1"},
      {"static_batches = 1", "at least 2"},
      {"model_samples_per_revolution = 8", "at least 16"},
      {"outlier_threshold = 2.5", "between 3 and 1e6"},
      {"outlier_block_samples = 8", "between 16 and 4096"},
  };
  for (const auto& [line, why] : bad) {
    const std::string key(std::string_view(line).substr(0, std::string_view(line).find(' ')));
    const std::string value(std::string_view(line).substr(std::string_view(line).find("= ") + 2));
    const std::string input = std::string("[reduce]\n# a comment\n") + line + "\n";
    expect_refused(input, 3, "reduce." + key + " must", why);
    // The value at fault is quoted (shortest form, so 90.0 reads "90").
    const std::string message = error_of(input);
    EXPECT_NE(message.find(", not "), std::string::npos) << message;
  }
  expect_refused("[reduce]\nrate_tolerance = 0.7\n", 2, "reduce.rate_tolerance must be in (0, 0.5), not 0.7",
                 "");
}

TEST(ConfigReduce, WrongTypesAndUnknownKeysAreRefused) {
  expect_refused("[reduce]\nencoder_glitch_rows = 2.5\n", 2, "reduce.encoder_glitch_rows",
                 "must be an integer");
  expect_refused("[reduce]\nlinear_drift = 1\n", 2, "reduce.linear_drift", "must be true or false");
  expect_refused("[reduce]\nrate_tolerance = \"2e-3\"\n", 2, "reduce.rate_tolerance", "must be a number");
  expect_refused("[reduce]\nrate_tolerance = nan\n", 2, "reduce.rate_tolerance", "finite");
  expect_refused("[reduce]\n\nrate_tol = 1e-3\n", 3, "unknown key reduce.rate_tol", "rate_tolerance");
  expect_refused("[reduce]\nmethod = \"window\"\n", 2, "unknown key reduce.method", "expected one of");
  expect_refused("[calibration]\nreduction = \"mean\"\n", 2, "calibration.reduction",
                 "\"harmonic\" or \"window\"");
  expect_refused("reduce = 3\n", 1, "reduce", "must be a table");
}

// ---- one rate, one place: [centrifuge] rate_rad_s and [test] rates_rad_s (issue 20, item 7) ---------------

/// The 1-based line of text on which `what` begins.
int line_of(const std::string& text, const std::string& what) {
  const std::size_t at = text.find(what);
  EXPECT_NE(at, std::string::npos) << what;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

TEST(ConfigRates, ACentrifugeRateThatIsNotATestRateIsRefusedNamingBothKeys) {
  // The issue's case: the file `init` writes, its [centrifuge] rate_rad_s set to 5.0 while [test] still says
  // rates_rad_s = [9.9]. The test would run at 9.9 rad/s: one of the two keys would be ignored.
  std::string text = scenario_to_toml(default_scenario());
  const std::string commented = "# rate_rad_s = 9.9";
  const std::size_t at = text.find(commented);
  ASSERT_NE(at, std::string::npos) << text;
  text.replace(at, commented.size(), "rate_rad_s = 5.0");
  const std::string message = error_of(text);
  EXPECT_NE(message.find("bad.toml, line " + std::to_string(line_of(text, "rate_rad_s = 5.0")) +
                         ": centrifuge.rate_rad_s = 5 is not one of test.rates_rad_s = [9.9] (line " +
                         std::to_string(line_of(text, "rates_rad_s = [9.9]")) + ")"),
            std::string::npos)
      << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  // The same by hand, the test's rates first.
  expect_refused("[test]\nrates_rad_s = [0, 3.0]\n[centrifuge]\nrate_rad_s = 5.5\n", 4,
                 "centrifuge.rate_rad_s = 5.5 is not one of test.rates_rad_s = [0, 3] (line 2)",
                 "give the rates in test.rates_rad_s alone");
}

TEST(ConfigRates, EitherKeyAloneOrBothAgreeingIsRead) {
  // [test] rates_rad_s alone: the centrifuge's rate (`inputs`' rate) follows its first non-zero rate.
  const Scenario rates = parse_scenario("[test]\nrates_rad_s = [0, 3.0, 7.0]\n", "rates.toml");
  EXPECT_EQ(rates.centrifuge.rate_rad_s, 3.0);
  EXPECT_EQ(rates.test.rates_rad_s, (std::vector<double>{0.0, 3.0, 7.0}));
  // A static test keeps the default scenario's rate (it sizes the holds without static_hold_s).
  const Scenario stopped = parse_scenario("[test]\nrates_rad_s = [0]\n", "stopped.toml");
  EXPECT_EQ(stopped.centrifuge.rate_rad_s, default_scenario().centrifuge.rate_rad_s);
  // Both, the centrifuge's rate one of the test's (not the first: `inputs` at the second rate).
  const Scenario both =
      parse_scenario("[centrifuge]\nrate_rad_s = 7.0\n[test]\nrates_rad_s = [0, 3.0, 7.0]\n", "both.toml");
  EXPECT_EQ(both.centrifuge.rate_rad_s, 7.0);
  // A static test with the centrifuge's rate: any rate (the one its holds are sized by).
  const Scenario hold =
      parse_scenario("[centrifuge]\nrate_rad_s = 5.5\n[test]\nrates_rad_s = [0]\n", "h.toml");
  EXPECT_EQ(hold.centrifuge.rate_rad_s, 5.5);
  EXPECT_EQ(hold.test.rates_rad_s, std::vector<double>{0.0});
}

TEST(ConfigRates, InitWritesTheRateOnceSoEditingTheTestRatesMovesBoth) {
  const std::string init = scenario_to_toml(default_scenario());
  // rate_rad_s is there, commented out: the only rate the reader sees is [test] rates_rad_s.
  EXPECT_NE(init.find("\n# rate_rad_s = 9.9 "), std::string::npos) << init;
  EXPECT_EQ(init.find("\nrate_rad_s ="), std::string::npos) << init;
  std::string edited = init;
  const std::string rates = "rates_rad_s = [9.9]";
  edited.replace(edited.find(rates), rates.size(), "rates_rad_s = [0.0, 5.0]");
  const Scenario s = parse_scenario(edited, "edited.toml");
  EXPECT_EQ(s.centrifuge.rate_rad_s, 5.0);
  EXPECT_EQ(s.test.rates_rad_s, (std::vector<double>{0.0, 5.0}));
}

TEST(ConfigRates, AScenarioWhoseRatesDisagreeIsNotWritten) {
  Scenario s = default_scenario();
  s.centrifuge.rate_rad_s = 5.0;  // the test still at 9.9: a file holding both would be refused
  try {
    (void)scenario_to_toml(s);
    ADD_FAILURE() << "written";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("rate_rad_s 5 is not one of its [test] rates_rad_s [9.9]"), std::string::npos)
        << message;
  }
}

// ---- a static hold's own duration: [test] static_hold_s (issue 20, item 7) ------------------------------

/// The durations of the timeline's measurements of `kind`, s.
std::vector<double> durations(const Timeline& t, SegmentKind kind) {
  std::vector<double> out;
  for (const MeasurementInterval& m : t.measurements)
    if (m.kind == kind) out.push_back(m.end_s - m.start_s);
  return out;
}

TEST(ConfigStaticHold, AStaticHoldLastsStaticHoldS) {
  const Scenario s =
      parse_scenario("[test]\nrates_rad_s = [0, 9.9]\nrevolutions = 20\nstatic_hold_s = 7.5\n", "hold.toml");
  EXPECT_EQ(s.test.static_hold_s, 7.5);
  const Timeline t = make_timeline(s.test, s.model());
  const std::vector<double> holds = durations(t, SegmentKind::kHold);
  ASSERT_EQ(holds.size(), 16u);  // 4 betas x 4 gammas at rate 0
  for (const double h : holds) EXPECT_NEAR(h, 7.5, 1e-9);
  // The spinning dwells keep their whole revolutions: 20 periods of 9.9 rad/s.
  for (const double d : durations(t, SegmentKind::kDwell))
    EXPECT_NEAR(d, 20 * 2 * std::numbers::pi / 9.9, 1e-9);
  // The issue's 5.3 h static record: one key, not revolutions = 30000.
  const Scenario day = parse_scenario(
      "[test]\nrates_rad_s = [0]\nbeta_deg = [0]\ngamma_deg = [0]\nstatic_hold_s = 19080\n", "day.toml");
  const std::vector<double> day_holds = durations(make_timeline(day.test, day.model()), SegmentKind::kHold);
  ASSERT_EQ(day_holds.size(), 1u);
  EXPECT_NEAR(day_holds[0], 5.3 * 3600, 1e-6);
  // The test's size counts the holds at their own length: 16 holds of (7.5 s + 2 s settle) and 4 dwells of
  // (20 periods + 2 s), at 200 Hz.
  EXPECT_NEAR(planned_test_samples(s.test, s.centrifuge.rate_rad_s),
              (16 * (7.5 + 2.0) + 4 * (20 * 2 * std::numbers::pi / 9.9 + 2.0)) * 200.0, 1e-6);
  expect_refused("[test]\nstatic_hold_s = -1.0\n", 2, "test.static_hold_s", ">= 0");
}

TEST(ConfigStaticHold, WithoutTheKeyAHoldLastsTheRevolutionsOfTheFirstSpinningRateAsBefore) {
  const Scenario s = parse_scenario("[test]\nrates_rad_s = [0, 4.0, 9.9]\nrevolutions = 30\n", "old.toml");
  EXPECT_EQ(s.test.static_hold_s, 0.0);
  const Timeline t = make_timeline(s.test, s.model());
  for (const double h : durations(t, SegmentKind::kHold))
    EXPECT_NEAR(h, 30 * 2 * std::numbers::pi / 4.0, 1e-9);
  // init writes the key with its default, which reads back as the old rule.
  EXPECT_NE(scenario_to_toml(default_scenario()).find("\nstatic_hold_s = 0.0 "), std::string::npos);
}

TEST(ConfigStaticHold, AStaticTestWithoutAnyRateIsSimulatedAndReducedWithItsOwnHolds) {
  // No rate anywhere (the centrifuge's is 0 too): before static_hold_s such a test could not be planned.
  const Scenario s = parse_scenario(
      "[centrifuge]\nrate_rad_s = 0.0\n[test]\nrates_rad_s = [0]\nbeta_deg = [0, 90]\nstatic_hold_s = 4.0\n"
      "settle_s = 1.0\n",
      "static.toml");
  const Reduction r = testing::simulate_and_reduce(s, 1);
  ASSERT_EQ(r.dwells.size(), 8u);  // 2 betas x 4 gammas
  for (const Dwell& d : r.dwells) {
    EXPECT_TRUE(d.is_static);
    EXPECT_NEAR(d.planned_duration_s, 4.0, 1e-9);
    // 4 s at 200 Hz, less the samples the reducer's guards drop at the ends.
    EXPECT_GT(d.samples, 700u);
    EXPECT_LE(d.samples, 801u);
  }
}

// ---- README's static record for `noise` (issue 20, item 7) ------------------------------------------------

TEST(ConfigStaticHold, ReadmeSimulatesTheStaticRecordThatNoiseReads) {
  // The commands of README.md's block after the marker "static-record", run as written (build/gyrocal is this
  // build's command line), so that the README cannot drift from what works.
  const std::string readme =
      test::slurp(std::filesystem::path(GYROCAL_TEST_DATA_DIR) / ".." / ".." / "README.md");
  const std::size_t marker = readme.find("<!-- static-record");
  ASSERT_NE(marker, std::string::npos);
  const std::size_t begin = readme.find("```sh\n", marker);
  ASSERT_NE(begin, std::string::npos);
  const std::size_t end = readme.find("\n```", begin + 6);
  ASSERT_NE(end, std::string::npos);
  const std::string block = readme.substr(begin + 6, end + 1 - (begin + 6));
  const std::filesystem::path dir = test::fresh_test_folder("gyrocal-readme");
  std::filesystem::create_directories(dir / "build");
  std::filesystem::create_symlink(GYROCAL_CLI, dir / "build" / "gyrocal");
  { std::ofstream(dir / "block.sh") << block; }
  const std::string command = "cd '" + dir.string() + "' && sh -e block.sh >out.txt 2>err.txt";
  ASSERT_EQ(std::system(command.c_str()), 0) << block << test::slurp(dir / "err.txt");
  // The record: the main axis stopped, one hour at 100 Hz.
  std::ifstream record(dir / "static.csv");
  std::string line;
  std::size_t rows = 0;
  double last_time = 0.0;
  while (std::getline(record, line)) {
    if (line.empty() || line[0] == '#' || line.starts_with("time_s")) continue;
    std::istringstream fields(line);
    std::string time, main;
    std::getline(fields, time, ',');
    std::getline(fields, main, ',');
    last_time = std::stod(time);
    EXPECT_NEAR(std::stod(main), 0.0, 1e-6) << line;
    if (HasFailure()) break;
    ++rows;
  }
  EXPECT_NEAR(last_time, 3600.0, 0.02);
  EXPECT_NEAR(static_cast<double>(rows), 3600.0 * 100, 2.0);
  // noise read it and found the configured angle random walk, 0.002 deg/sqrt(h) (an hour at 100 Hz measures
  // it to about 0.2 %).
  const nlohmann::json noise = nlohmann::json::parse(test::slurp(dir / "noise.json"));
  ASSERT_TRUE(noise.contains("terms")) << noise.dump();
  EXPECT_NEAR(noise["terms"]["angle_random_walk_deg_rt_h"]["value"].get<double>(), 0.002, 0.02 * 0.002)
      << noise.dump();
  std::filesystem::remove_all(dir);
}

// ---- files ----------------------------------------------------------------------------------------------

TEST(ConfigFile, MissingFileIsNamed) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "gyrocal-no-such-dir" / "missing.toml";
  try {
    load_scenario(path);
    ADD_FAILURE() << "a missing file was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

TEST(ConfigFile, LoadsAFileAndNamesItInErrors) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("gyrocal-test-config-" + std::to_string(::getpid()) + ".toml");
  {
    std::ofstream out(path);
    out << scenario_to_toml(changed_scenario());
  }
  expect_same(load_scenario(path), changed_scenario());
  {
    std::ofstream out(path);
    out << "[centrifuge]\nradius_m = -3\n";
  }
  try {
    load_scenario(path);
    ADD_FAILURE() << "a negative radius was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string() + ", line 2: centrifuge.radius_m"), std::string::npos)
        << e.what();
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace gyrocal
