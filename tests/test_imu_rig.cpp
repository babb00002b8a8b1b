// A whole IMU's rig-like record through the command line (issue 27, "Done when"; docs/imu.md): a record of
// this test's own generator (tests/support/rig_imu_record.hpp: the rig's own order, ramps, longer dwells,
// the drive's rate offset and ripple; every channel an increment, its exact output integrated by the
// generator's own quadrature), written as a rig writes it (';', its own column names in its own order, time
// in integer ms, encoder counts, a sample counter the reader skips, lost rows, spikes in two channels), then
// `gyrocal calibrate --json` with the radius error and stretch estimated: every channel's every coefficient
// and both machine errors within 4.5 sigma of the generator's truth, and data_quality naming what was lost.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "support/cli_run.hpp"
#include "support/rig_imu_record.hpp"
#include "support/sanitized.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;

/// The main and counter encoders' counts per revolution (2^24) and the position encoder's (0.002 deg).
constexpr double kCounts = 16777216.0;
constexpr double kPositionCounts = 180000.0;
/// The truth's arm: 20 um longer than nominal, stretching by 1e-7 m/(rad/s)^2 (the demo IMU's).
constexpr double kRadiusError = 20e-6;
constexpr double kRadiusStretch = 1e-7;

/// The rig's own column names, by the default IMU's channel (gx gy gz ax ay az), and the order it writes
/// them in (the accelerometers first).
const std::map<std::string, std::string> kColumn = {{"gx", "dAngX"}, {"gy", "dAngY"}, {"gz", "dAngZ"},
                                                    {"ax", "dVelX"}, {"ay", "dVelY"}, {"az", "dVelZ"}};
const std::vector<std::size_t> kWriteOrder = {3, 4, 5, 0, 1, 2};

/// The default IMU (its six channels, their truths, the default machine's errors) on a short plan: the
/// default's rates, beta and gamma, 6 revolutions a dwell, 4 s static holds, 2 s of settling, at 100 Hz (the
/// sanitizer build: 4 revolutions at 50 Hz); the arm as kRadiusError and kRadiusStretch say.
Scenario rig_imu_truth() {
  Scenario s = default_imu_scenario();
  const bool small = testing::sanitized();
  s.test.revolutions = small ? 4 : 6;
  s.test.static_hold_s = 4.0;
  s.test.settle_s = 2.0;
  s.test.sample_rate_hz = small ? 50.0 : 100.0;
  s.errors.radius_error_m = kRadiusError;
  s.errors.radius_stretch_m_per_rad2_s2 = kRadiusStretch;
  for (SensorChannel& c : s.imu_channels) c.output.column = kColumn.at(c.name);
  return s;
}

/// The configuration the lab calibrates with: the truth's machine with a nominal arm, the radius error and
/// stretch to estimate, and the rig's [record]: ';', time in ms, the angles as encoder counts.
Scenario rig_imu_config(const Scenario& truth) {
  Scenario c = truth;
  c.errors.radius_error_m = 0.0;
  c.errors.radius_stretch_m_per_rad2_s2 = 0.0;
  c.estimate = {"radius_error", "radius_stretch"};
  RecordLayout r;
  r.delimiter = ';';
  r.time_column = "t_ms";
  r.time_unit = TimeUnit::kMilliseconds;
  r.main_angle_column = "enc_main";
  r.counter_angle_column = "enc_counter";
  r.position_angle_column = "enc_beta";
  r.main_counts_per_revolution = static_cast<std::int64_t>(kCounts);
  r.counter_counts_per_revolution = static_cast<std::int64_t>(kCounts);
  r.position_counts_per_revolution = static_cast<std::int64_t>(kPositionCounts);
  c.record = r;
  return c;
}

/// The rig's imperfections of the machine's motion: the drive turns 1e-3 fast with a ripple of 2e-4 at
/// 0.37 Hz; and of its acquisition: quantised encoders, a toggling position encoder, a clock and a counter
/// that do not start at zero, rows lost in four dwells (three single rows and a run of three) and spikes in
/// gy and az.
struct RigPlan {
  testing::RigImperfections motion_errors;
  testing::RigMotion motion;
  testing::RigImuAcquisition acquisition;
};
RigPlan rig_plan() {
  RigPlan p;
  p.motion_errors.rate_offset = 1e-3;
  p.motion_errors.ripple = 2e-4;
  p.motion_errors.ripple_hz = 0.37;
  p.motion.move_s = 2.0;
  p.motion.extra_dwell_s = 2.0;
  testing::RigImuAcquisition& a = p.acquisition;
  a.angle_quantum_deg = 360.0 / kCounts;
  a.position_count_deg = 360.0 / kPositionCounts;
  a.start_ms = 73'912'345;
  a.first_count = 500'000;
  // Dwells in the rig's order: 0-3 at 12 rad/s (3.1 s planned after 2 s of settling), 4-7 at 6 rad/s
  // (6.3 s), then the 32 static holds (4 s), each phase 2 s longer (the sanitizer build's 4 revolutions:
  // 2.1 and 4.2 s). Each event lies inside a measured part. A static hold's steady run may start during
  // the counter platform's 2 s index (a 0.5 s window of the index can lie on a line within
  // angle_tolerance_deg; seen 1.4 s before the index ends), and its settle time then runs out before the
  // hold's; 3.0 to 3.3 s into the hold lies inside its measured part wherever in the index the run starts.
  a.lost = {{1, 3.5, 1}, {5, 5.0, 3}, {10, 3.0, 1}, {30, 3.3, 1}};
  a.spikes = {{2, 3.0, 1, 2e5}, {6, 4.5, 1, -2e5}, {12, 3.1, 5, 0.5}, {3, 3.2, 5, -0.5}, {20, 3.2, 5, 0.5}};
  return p;
}

/// Writes the rig's record of `truth`: ';', time in ms, the counter, encoder counts, the channels'
/// increments in the rig's order, its own names. Returns the rows written.
std::size_t write_rig_imu_record(const fs::path& path, const Scenario& truth, const RigPlan& plan,
                                 std::uint64_t seed) {
  std::ofstream out(path);
  out << "sample;t_ms;enc_main;enc_counter;enc_beta";
  for (std::size_t c : kWriteOrder) out << ';' << truth.imu_channels[c].output.column;
  out << '\n';
  const double q = 360.0 / kCounts, qb = 360.0 / kPositionCounts;
  std::size_t rows = 0;
  testing::rig_imu_rows(
      truth, plan.motion_errors, plan.motion, plan.acquisition, seed, [&](const testing::RigImuRow& r) {
        out << fmt::format("{};{};{:.0f};{:.0f};{:.0f}", r.count, r.time_ms, std::round(r.main_angle_deg / q),
                           std::round(r.counter_angle_deg / q), std::round(r.position_angle_deg / qb));
        for (std::size_t c : kWriteOrder) out << fmt::format(";{:.17g}", r.increments[c]);
        out << '\n';
        ++rows;
      });
  return rows;
}

/// The truth of coefficient `name` of channel `c`, in the result's units: a gyro's drift in deg/h (per g,
/// per g^2), an accelerometer's in its table's units with K1 as output_scale times the truth's ratio.
double truth_of(const SensorChannel& c, const std::string& name) {
  if (const auto* g = std::get_if<Gyro>(&c.sensor)) {
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
      if (kGyroParameters[k].name == name) return g->drift.values[k];
  } else {
    const auto& a = std::get<Accelerometer>(c.sensor);
    for (std::size_t k = 0; k < kNumAccelCoefficients; ++k)
      if (kAccelerometerParameters[k].name == name)
        return (name == "K1" ? c.output.scale : 1.0) * a.coefficients.values[k];
  }
  ADD_FAILURE() << c.name << " has no coefficient " << name;
  return 0.0;
}

/// The rig's record of `truth` with `plan` and `seed`, written to DIR/rec.csv and calibrated through the
/// command line (`calibrate rec.csv --config imu.toml --json out.json`, the configuration rig_imu_config's):
/// the result's JSON. `rows`: the rows written.
nlohmann::json calibrate_rig_record(const fs::path& dir, const Scenario& truth, const RigPlan& plan,
                                    std::uint64_t seed, std::size_t* rows = nullptr) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t written = write_rig_imu_record(dir / "rec.csv", truth, plan, seed);
  if (rows) *rows = written;
  std::ofstream(dir / "imu.toml") << scenario_to_toml(rig_imu_config(truth));
  const auto generated = std::chrono::steady_clock::now();
  const test::CliOutcome o =
      test::run_cli("calibrate " + (dir / "rec.csv").string() + " --config " + (dir / "imu.toml").string() +
                        " --json " + (dir / "out.json").string(),
                    dir);
  EXPECT_EQ(o.status, 0) << o.err << "\n" << o.out;
  if (o.status != 0) return nlohmann::json::object();
  const auto end = std::chrono::steady_clock::now();
  std::printf("%zu rows, generated in %.1f s, calibrated in %.1f s\n", written,
              std::chrono::duration<double>(generated - start).count(),
              std::chrono::duration<double>(end - generated).count());
  return nlohmann::json::parse(test::slurp(dir / "out.json"));
}

TEST(ImuRig, ARigsRecordCalibratesEveryChannelAndTheRadiusWithinFourAndAHalfSigma) {
  const fs::path dir = test::fresh_test_folder("imu_rig");
  const Scenario truth = rig_imu_truth();
  const RigPlan plan = rig_plan();
  std::size_t rows = 0;
  const nlohmann::json j = calibrate_rig_record(dir, truth, plan, 27, &rows);
  ASSERT_FALSE(j.empty());
  EXPECT_EQ(j.at("rank"), j.at("unknowns"));
  EXPECT_EQ(j.at("unknowns").get<int>(), 3 * 10 + 3 * 11 + 2);

  // Every channel's every coefficient within 4.5 sigma of its truth.
  ASSERT_EQ(j.at("channels").size(), truth.imu_channels.size());
  for (const SensorChannel& c : truth.imu_channels) {
    SCOPED_TRACE(c.name);
    const nlohmann::json& coefficients = j.at("channels").at(c.name).at("coefficients");
    EXPECT_EQ(coefficients.size(), std::holds_alternative<Gyro>(c.sensor) ? 10u : 11u);
    double worst = 0.0;
    std::string worst_name;
    for (const auto& [name, e] : coefficients.items()) {
      ASSERT_TRUE(e.at("identifiable").get<bool>()) << name;
      const double sd = e.at("std").get<double>();
      ASSERT_GT(sd, 0.0) << name;
      const double z = (e.at("value").get<double>() - truth_of(c, name)) / sd;
      EXPECT_LE(std::abs(z), 4.5) << name << ": " << e.at("value").get<double>() << " against "
                                  << truth_of(c, name) << ", std " << sd;
      if (std::abs(z) > std::abs(worst)) {
        worst = z;
        worst_name = name;
      }
    }
    std::printf("%s: worst z %+.2f (%s), outliers %d\n", c.name.c_str(), worst, worst_name.c_str(),
                j.at("channels").at(c.name).at("outliers").get<int>());
  }
  // The radius error and stretch.
  ASSERT_EQ(j.at("machine_errors").size(), 2u);
  const std::map<std::string, double> errors = {{"radius_error", kRadiusError},
                                                {"radius_stretch", kRadiusStretch}};
  for (const nlohmann::json& e : j.at("machine_errors")) {
    const std::string name = e.at("error").get<std::string>();
    ASSERT_TRUE(e.at("identifiable").get<bool>()) << name;
    const double z = (e.at("value").get<double>() - errors.at(name)) / e.at("std").get<double>();
    std::printf("%s: %.6g (truth %.6g), std %.3g, z %+.2f\n", name.c_str(), e.at("value").get<double>(),
                errors.at(name), e.at("std").get<double>(), z);
    EXPECT_LE(std::abs(z), 4.5) << name;
  }

  // What the rig lost: each run of lost rows inside a dwell's measured part leaves one increment without a
  // known interval (the row after it), dropped; the spikes are outliers of their own channels.
  const nlohmann::json& q = j.at("data_quality");
  std::printf("data_quality: rows_read %d, increments_dropped %d, gaps %d, outliers %d\n",
              q.at("rows_read").get<int>(), q.at("increments_dropped").get<int>(), q.at("gaps").get<int>(),
              q.at("outliers").get<int>());
  EXPECT_EQ(q.at("rows_read").get<std::size_t>(), rows);
  EXPECT_EQ(q.at("increments_dropped").get<std::size_t>(), plan.acquisition.lost.size());
  EXPECT_EQ(q.at("gaps").get<std::size_t>(), plan.acquisition.lost.size());
  std::map<std::size_t, int> spikes;
  for (const auto& s : plan.acquisition.spikes) ++spikes[s.channel];
  int spiked = 0;
  for (const auto& [c, count] : spikes) {
    const std::string& name = truth.imu_channels[c].name;
    EXPECT_GE(j.at("channels").at(name).at("outliers").get<int>(), count) << name;
    spiked += count;
  }
  EXPECT_GE(q.at("outliers").get<int>(), spiked);
  if (!HasFailure()) fs::remove_all(dir);
}

TEST(ImuRig, ADriveRippleDoesNotInflateTheStatedUncertainties) {
  // docs/accelerometer_internals.md, "The drive's ripple": a ripple of 2e-4 at 0.37 Hz moves the centripetal
  // force at 12 g by 5 mg between revolutions, against ~0.1 mg of noise a revolution; the model terms follow
  // it, so the levels are the scatter of the output less the model. The same record with and without the
  // ripple (same seed, same noise): every stated std within 1.2x. The IMU's path once took the
  // accelerometers' levels from the output's own scatter between revolutions, ripple and all: its stds came
  // out 30-50x the smooth record's (K1 3.7e-4 against 1.2e-5 m/s^2/g, the radius error 38 um against 1.4 um),
  // its chi2 0.09 on 76 degrees of freedom.
  const fs::path dir = test::fresh_test_folder("imu_rig_ripple");
  const Scenario truth = rig_imu_truth();
  RigPlan smooth = rig_plan();
  smooth.motion_errors.ripple = 0.0;
  const nlohmann::json rippled = calibrate_rig_record(dir, truth, rig_plan(), 5);
  const nlohmann::json flat = calibrate_rig_record(dir, truth, smooth, 5);
  ASSERT_FALSE(rippled.empty());
  ASSERT_FALSE(flat.empty());
  double lo = 1e300, hi = 0.0;
  const auto compare = [&](const nlohmann::json& a, const nlohmann::json& b, const std::string& what) {
    const double ratio = a.at("std").get<double>() / b.at("std").get<double>();
    lo = std::min(lo, ratio);
    hi = std::max(hi, ratio);
    EXPECT_LT(ratio, 1.2) << what;
    EXPECT_GT(ratio, 1.0 / 1.2) << what;
  };
  for (const SensorChannel& c : truth.imu_channels)
    for (const auto& [name, e] : rippled.at("channels").at(c.name).at("coefficients").items())
      compare(e, flat.at("channels").at(c.name).at("coefficients").at(name), c.name + "." + name);
  for (std::size_t k = 0; k < 2; ++k)
    compare(rippled.at("machine_errors").at(k), flat.at("machine_errors").at(k),
            rippled.at("machine_errors").at(k).at("error").get<std::string>());
  std::printf("stated std rippled / smooth: %.3f to %.3f\n", lo, hi);
  if (!HasFailure()) fs::remove_all(dir);
}

}  // namespace
}  // namespace gyrocal
