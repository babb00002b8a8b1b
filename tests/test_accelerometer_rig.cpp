// An accelerometer's rig-like records through the real path (issue 19, "Done when"; docs/accelerometer.md):
// records of the test generator (tests/support/rig_record.hpp: its own order, ramps, extra dwell time, the
// IEEE 1293 output at the exact specific force of its own joint states), written as a rig writes them (ms,
// encoder counts, ';', a channel in mV/g with a zero offset), read through [record] and calibrated by
// calibrate_record or the command line; the estimates against the generator's truth.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/model/machine_errors.hpp"
#include "support/cli_run.hpp"
#include "support/rig_record.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;

/// The rig's channel: its true scale (the generator's K1, mV/g), the nominal scale a user configures and the
/// zero offset (mV).
constexpr double kTrueMilliVoltPerG = 2500.37;
constexpr double kNominalMilliVoltPerG = 2500.0;
constexpr double kZeroMilliVolt = 12.5;
/// The main and counter encoders' counts per revolution, and the position encoder's (0.002 deg a count).
constexpr double kPositionCounts = 180000.0;

/// A small two-speed test on the default machine (its wobbles and runouts in the truth and the
/// configuration alike): a static set at four gamma, 6 and 12 rad/s, four beta, 8 revolutions at 50 Hz, the
/// default truth with K1 the rig's mV/g.
Scenario rig_accelerometer(bool noisy) {
  Scenario s = default_scenario();
  s.sensor_kind = SensorKind::kAccelerometer;
  s.accelerometer = Accelerometer{};
  s.accelerometer.coefficients[AccelCoefficient::K1] = kTrueMilliVoltPerG;
  if (!noisy) s.accelerometer.noise = AccelerometerNoise{};
  s.test.rates_rad_s = {0.0, 6.0, 12.0};
  s.centrifuge.rate_rad_s = 6.0;
  s.test.revolutions = 8;
  s.test.sample_rate_hz = 50.0;
  s.test.settle_s = 2.0;
  s.test.static_hold_s = 2.0;
  return s;
}

/// The rig's [record]: ms, encoder counts, ';', the channel in mV with its nominal scale and zero.
std::string record_toml(double counts) {
  return fmt::format(
      "[sensor]\nkind = \"accelerometer\"\n[record]\ndelimiter = \";\"\ntime_column = \"t_ms\"\n"
      "time_unit = \"ms\"\nmain_angle_column = \"theta\"\ncounter_angle_column = \"psi\"\n"
      "position_angle_column = \"beta\"\nmain_counts_per_revolution = {:.0f}\n"
      "counter_counts_per_revolution = {:.0f}\nposition_counts_per_revolution = {:.0f}\n"
      "output_column = \"U_mV\"\noutput_scale_per_g = {}\noutput_offset = {}\n",
      counts, counts, kPositionCounts, kNominalMilliVoltPerG, kZeroMilliVolt);
}

/// Every imperfection of the generator whose effect the calibration models exactly: its own order, ramps,
/// jitter and rounded stamps (the reducer's uniform grid), encoder counts of `counts` a turn, a toggling
/// position encoder, the drive's rate offset (the model terms follow the measured rate), a gap, a clock jump,
/// spikes, a beta glitch. No ripple (see ADriveRippleNeitherBiasesNorInflates).
testing::RigImperfections exactly_modelled(double counts) {
  testing::RigImperfections imp = testing::every_imperfection();
  imp.ripple = 0.0;
  imp.angle_quantum_deg = 360.0 / counts;
  imp.position_count_deg = 360.0 / kPositionCounts;
  return imp;
}

/// Writes the generator's rows for `truth` as the rig's record file.
void write_rig_record(const fs::path& path, const Scenario& truth, const testing::RigImperfections& imp,
                      std::uint64_t seed, double counts) {
  std::ofstream out(path);
  out << "t_ms;theta;psi;beta;U_mV\n";
  const double q = 360.0 / counts, qb = 360.0 / kPositionCounts;
  testing::rig_rows(truth, imp, testing::RigMotion{}, seed, [&](const testing::RigRow& r) {
    out << fmt::format("{:.17g};{:.0f};{:.0f};{:.0f};{:.17g}\n", r.time_s * 1e3,
                       std::round(r.main_angle_deg / q), std::round(r.counter_angle_deg / q),
                       std::round(r.position_angle_deg / qb), kZeroMilliVolt + r.output);
  });
}

/// calibrate_record on the rig's file through its [record].
CalibrationResult calibrate_rig(const fs::path& path, const Scenario& config, double counts,
                                const std::vector<std::string>& estimate = {}) {
  const Scenario rig = parse_scenario(record_toml(counts), "rig.toml");
  CalibrationOptions o;
  o.sensor = SensorKind::kAccelerometer;
  if (!estimate.empty()) o.estimate = parse_machine_error_names(estimate, "test");
  return calibrate_record(path.string(), config.model(), config.test, o, rig.record);
}

/// The tolerance of coefficient k noise-free: 1e-4 of its unit, K1 1e-9 relative.
double noise_free_tolerance(std::size_t k) {
  return k == 1 ? 1e-9 * kTrueMilliVoltPerG : 1e-4;
}

class AccelerometerRig : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::fresh_test_folder("arig"); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(AccelerometerRig, NoiseFreeRecordGivesAllElevenAndK1InTheRigsMillivoltsPerG) {
  // Encoders of 2^32 counts a turn: the line through a dwell's readings then misses the arm's phase by
  // ~q / sqrt(12 N) ~ 1e-11 rad, which turns the first harmonic into delta_p, delta_o, Kip, Kio by far less
  // than 1e-4 of their units (measured: 6e-6 urad of delta_p). With 2^20 counts the same record misses by
  // 3e-3 urad of delta_p, 2e-3 ug/g^2 of Kip, Kio and Kpp, 2 nm of the radius: the rounding of the readings,
  // not the calibration, is then what limits it. The truth's K1 is the generator's 2500.37 mV/g, the
  // configured scale a nominal 2500: K1 comes back as the true scale (an independent route to
  // output_scale_per_g x the fitted ratio).
  const double counts = 4294967296.0;
  const Scenario s = rig_accelerometer(false);
  const fs::path path = dir_ / "rig.csv";
  write_rig_record(path, s, exactly_modelled(counts), 1, counts);
  const CalibrationResult r = calibrate_rig(path, s, counts);
  ASSERT_EQ(r.coefficients.size(), kNumAccelCoefficients);
  EXPECT_EQ(r.rank, 11);
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    const CoefficientEstimate& c = r.coefficients[k];
    ASSERT_TRUE(c.identifiable) << c.name;
    std::printf("%s: %.12g (truth %.12g)\n", c.name.c_str(), c.value, s.accelerometer.coefficients.values[k]);
    EXPECT_NEAR(c.value, s.accelerometer.coefficients.values[k], noise_free_tolerance(k)) << c.name;
  }
  EXPECT_NEAR(r.coefficients[1].value, kTrueMilliVoltPerG, 1e-9 * kTrueMilliVoltPerG);

  // The radius error from the sensor: the truth's arm 30 um long, the configuration's nominal; through the
  // command line (calibrate --estimate radius_error --json).
  Scenario truth = s;
  truth.errors.radius_error_m = 30e-6;
  write_rig_record(dir_ / "radius.csv", truth, exactly_modelled(counts), 2, counts);
  Scenario config = s;
  config.record = parse_scenario(record_toml(counts), "rig.toml").record;
  const test::CliOutcome o =
      test::calibrate_in(dir_, "radius.csv", scenario_to_toml(config), " --estimate radius_error");
  ASSERT_EQ(o.status, 0) << o.err;
  const nlohmann::json j = nlohmann::json::parse(o.out);
  ASSERT_EQ(j.at("machine_errors").size(), 1u);
  const nlohmann::json& e = j.at("machine_errors").at(0);
  EXPECT_EQ(e.at("error"), "radius_error");
  ASSERT_TRUE(e.at("identifiable").get<bool>()) << e.dump();
  std::printf("radius_error: %.6g (truth 30e-6 m, unit %s)\n", e.at("value").get<double>(),
              e.at("unit").get<std::string>().c_str());
  EXPECT_NEAR(e.at("value").get<double>(), 30e-6, 1e-10) << e.dump();
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    const std::string name(kAccelerometerParameters[k].name);
    EXPECT_NEAR(j.at("coefficients").at(name).at("value").get<double>(),
                s.accelerometer.coefficients.values[k], noise_free_tolerance(k))
        << name;
  }
}

/// Mean and standard deviation of `v`.
std::pair<double, double> mean_std(const std::vector<double>& v) {
  const auto n = static_cast<double>(v.size());
  double mean = 0.0, sq = 0.0;
  for (double x : v) mean += x / n;
  for (double x : v) sq += (x - mean) * (x - mean);
  return {mean, std::sqrt(sq / (n - 1.0))};
}

/// z-scores of the eleven and the radius error over `seeds` rig records (10 ug/sqrt(Hz), every exactly
/// modelled imperfection, encoders of 2^24 counts a turn, whose phase miss ~1e-9 rad is far below the
/// noise's) with a drive ripple of `ripple` at 0.37 Hz, each calibrated with --estimate radius_error against
/// a truth whose arm is 30 um long; and the mean stated std of each.
struct ZScores {
  std::vector<std::vector<double>> z, std;
};
ZScores z_scores(const fs::path& dir, double ripple, int seeds) {
  const double counts = 16777216.0;
  const Scenario config = rig_accelerometer(true);
  Scenario truth = config;
  truth.errors.radius_error_m = 30e-6;
  ZScores out;
  out.z.resize(kNumAccelCoefficients + 1);
  out.std.resize(kNumAccelCoefficients + 1);
  const fs::path path = dir / "rig.csv";
  testing::RigImperfections imp = exactly_modelled(counts);
  imp.ripple = ripple;
  for (int seed = 1; seed <= seeds; ++seed) {
    write_rig_record(path, truth, imp, static_cast<std::uint64_t>(seed), counts);
    const CalibrationResult r = calibrate_rig(path, config, counts, {"radius_error"});
    for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
      const CoefficientEstimate& c = r.coefficients[k];
      EXPECT_TRUE(c.identifiable) << c.name;
      out.z[k].push_back((c.value - truth.accelerometer.coefficients.values[k]) / c.std);
      out.std[k].push_back(c.std);
    }
    EXPECT_EQ(r.machine_errors.size(), 1u);
    EXPECT_TRUE(r.machine_errors[0].identifiable) << r.machine_errors[0].reason;
    out.z.back().push_back((r.machine_errors[0].value - 30e-6) / r.machine_errors[0].std);
    out.std.back().push_back(r.machine_errors[0].std);
  }
  return out;
}

/// The std of z of 200 unit normals lies in [0.9, 1.1] with probability ~0.95; the band is [0.85, 1.15], and
/// the mean within 4 / sqrt(seeds).
void expect_unit_spread(const ZScores& zs, const char* what) {
  for (std::size_t k = 0; k <= kNumAccelCoefficients; ++k) {
    const std::string name =
        k < kNumAccelCoefficients ? std::string(kAccelerometerParameters[k].name) : "radius_error";
    const auto [mean, sd] = mean_std(zs.z[k]);
    std::printf("%s %s: z mean %.3f, std %.3f over %zu seeds\n", what, name.c_str(), mean, sd,
                zs.z[k].size());
    EXPECT_GE(sd, 0.85) << name;
    EXPECT_LE(sd, 1.15) << name;
    EXPECT_LT(std::abs(mean), 4.0 / std::sqrt(static_cast<double>(zs.z[k].size()))) << name;
  }
}

TEST_F(AccelerometerRig, NoisyZScoresOfTheElevenAndTheRadiusErrorHaveUnitSpread) {
  // 200 rig records without a ripple: (estimate - truth) / std spreads as a unit normal when the stated std
  // is honest.
  expect_unit_spread(z_scores(dir_, 0.0, 200), "smooth");
}

/// Calibrates the noise-free rig record of `s` with a drive ripple of 2e-4 (encoders of 2^32 counts, every
/// exactly modelled imperfection) and checks every coefficient against the truth: within `tolerance` of its
/// unit, K1 within 1e-9 relative; with `radius`, the truth's arm is 30 um long and its error, estimated
/// (--estimate radius_error), within a nanometre.
void expect_rippled_record_recovered(const fs::path& dir, const Scenario& s, double tolerance,
                                     bool radius = false) {
  const double counts = 4294967296.0;
  testing::RigImperfections imp = exactly_modelled(counts);
  imp.ripple = 2e-4;
  const fs::path path = dir / "rippled.csv";
  Scenario truth = s;
  if (radius) truth.errors.radius_error_m = 30e-6;
  write_rig_record(path, truth, imp, 1, counts);
  const CalibrationResult clean = calibrate_rig(
      path, s, counts, radius ? std::vector<std::string>{"radius_error"} : std::vector<std::string>{});
  if (radius) {
    ASSERT_EQ(clean.machine_errors.size(), 1u);
    std::printf("noise-free rippled, radius_error: error %.3g m\n", clean.machine_errors[0].value - 30e-6);
    // Measured 4.4e-10 m with the ripple (1e-10 m on a smooth record): a nanometre, a thousandth of the
    // sigma of a noisy record's estimate (~0.6 um).
    EXPECT_NEAR(clean.machine_errors[0].value, 30e-6, 1e-9);
  }
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    const CoefficientEstimate& c = clean.coefficients[k];
    ASSERT_TRUE(c.identifiable) << c.name;
    std::printf("noise-free rippled, %d revolutions at %g Hz, %s: error %.3g (std %.3g)\n",
                s.test.revolutions, s.test.sample_rate_hz, c.name.c_str(),
                c.value - s.accelerometer.coefficients.values[k], c.std);
    EXPECT_NEAR(c.value, s.accelerometer.coefficients.values[k], k == 1 ? noise_free_tolerance(k) : tolerance)
        << c.name;
  }
}

TEST_F(AccelerometerRig, ARippledRecordOfTheDefaultTestsDwellsGivesAllElevenWithinTheIssuesTolerance) {
  // The same noise-free rippled rig record as below, but with the dwells of `gyrocal init --sensor
  // accelerometer` (100 revolutions at 200 Hz) instead of the small test's 8 at 50 Hz: what the spline's
  // approximation of the ripple leaves near a dwell's ends shrinks with the dwell's length, and every
  // coefficient comes back within 1e-4 of its unit, K1 within 1e-9 (issue 19): measured at most 2.7e-5
  // (delta_p, urad; Kip 1.3e-5 ug/g^2), K1 4e-12 relative; a 30 um radius error within 4.4e-10 m. This record
  // found the spline's F-test reading a ripple the spline holds whole as unresolved (its scatter 0 by
  // rounding; reduce/measured_rate.cpp), which left the dwells on their lines and missed Kio by 0.5 ug/g^2.
  Scenario s = rig_accelerometer(false);
  const Scenario defaults = default_accelerometer_scenario();
  s.test.revolutions = defaults.test.revolutions;
  s.test.sample_rate_hz = defaults.test.sample_rate_hz;
  expect_rippled_record_recovered(dir_, s, 1e-4, true);
}

TEST_F(AccelerometerRig, ADriveRippleNeitherBiasesNorInflates) {
  // docs/accelerometer.md, "The drive's ripple". A ripple of 2e-4 at 0.37 Hz moves the centripetal force at
  // 12 g by 5 mg and its direction by as much again, against ~14 ug of noise a revolution.
  // Noise-free (encoders of 2^32 counts, every exactly modelled imperfection, spikes included): the model
  // terms follow the measured motion, reduced by the output's own operator (its basis angle, its outliers
  // left out), and every coefficient comes back as from a smooth record to the spline's approximation of the
  // ripple (reduce/measured_rate.hpp): measured 1.0e-3 ug/g^2 on Kip, 4.9e-4 urad on delta_p and below
  // 1.3e-4 of their units on the others (K1 2e-12 relative), against 6e-3 and 7e-3 with the dwell's one line
  // as the operator's angle and 2.8 ug/g^2 and 2.2 urad before that: within 1.5e-3 of each unit, K1 within
  // 1e-9. The issue's 1e-4 is not met for Kip and delta_p on these short dwells (it is on the default test's:
  // ARippledRecordOfTheDefaultTestsDwellsGivesAllElevenWithinTheIssuesTolerance).
  expect_rippled_record_recovered(dir_, rig_accelerometer(false), 1.5e-3);
  // Noisy, 200 seeds: the std is the residual's after the model, so z spreads as a unit normal, and the
  // stated std is the smooth records' (the same 20 seeds without the ripple: within 1.2x).
  const ZScores rippled = z_scores(dir_, 2e-4, 200);
  expect_unit_spread(rippled, "rippled");
  const ZScores smooth = z_scores(dir_, 0.0, 20);
  for (std::size_t k = 0; k <= kNumAccelCoefficients; ++k) {
    double ratio = 0.0;
    for (std::size_t i = 0; i < 20; ++i) ratio += rippled.std[k][i] / smooth.std[k][i] / 20.0;
    std::printf("stated std rippled / smooth, %zu: %.3f\n", k, ratio);
    EXPECT_LT(ratio, 1.2) << k;
    EXPECT_GT(ratio, 1.0 / 1.2) << k;
  }
}

}  // namespace
}  // namespace gyrocal
