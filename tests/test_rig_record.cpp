// A record written as a rig writes it, every imperfection at once, in the rig's own layout, calibrated
// through the command line and a [record] mapping (issue 8's "done when"; docs/physics.md section 14,
// docs/records.md).
//
// The rows come from tests/support/rig_record.hpp (its own timeline and the exact model, independent of the
// simulator); this file only writes them as a rig's data acquisition would: ';' between fields, integer
// milliseconds, encoder counts (wrapped), and the output in mV at 2.5 mV per deg/h.
#include <cmath>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/model/gyro.hpp"
#include "support/cli_run.hpp"
#include "support/rig_record.hpp"

namespace gyrocal {
namespace {

using test::calibrate_in;

constexpr std::int64_t kMainCounts = 3600;        // 0.1 deg per count, as the rig's quantum
constexpr std::int64_t kPositionCounts = 180000;  // 0.002 deg per count
constexpr double kMilliVoltPerDegH = 2.5;

/// A count in [0, per_rev): the encoder's reading of an angle in degrees that is a whole number of counts.
std::int64_t wrapped_count(double deg, std::int64_t per_rev) {
  const auto c = static_cast<std::int64_t>(std::llround(deg * static_cast<double>(per_rev) / 360.0));
  return ((c % per_rev) + per_rev) % per_rev;
}

void write_rig_layout(const std::filesystem::path& path, const std::vector<testing::RigRow>& rows) {
  std::ofstream out(path);
  out << "# DAQ export, station 2\n";
  out << "t_ms;gyro_mV;theta_cnt;psi_cnt;beta_cnt\n";
  out.precision(17);
  for (const testing::RigRow& r : rows)
    out << std::llround(r.time_s * 1e3) << ';' << r.output * kMilliVoltPerDegH << ';'
        << wrapped_count(r.main_angle_deg, kMainCounts) << ';'
        << wrapped_count(r.counter_angle_deg, kMainCounts) << ';'
        << wrapped_count(r.position_angle_deg, kPositionCounts) << '\n';
}

constexpr const char* kMapping = R"(
[record]
delimiter = ";"
comment = "#"
time_column = "t_ms"
time_unit = "ms"
main_angle_column = "theta_cnt"
counter_angle_column = "psi_cnt"
position_angle_column = "beta_cnt"
main_counts_per_revolution = 3600
counter_counts_per_revolution = 3600
position_counts_per_revolution = 180000
output_column = "gyro_mV"
output_scale_per_deg_h = 2.5
)";

TEST(RigRecord, EveryImperfectionAtOnceInTheRigsLayoutCalibratesToTheTruthThroughAMapping) {
  Scenario s = default_scenario();
  s.test.sample_rate_hz = 50.0;
  s.test.revolutions = 8;
  s.test.rates_rad_s = {9.9, 7.0};
  // Stamps rounded to whole ms, as the layout writes them; angles a whole number of counts.
  const testing::RigImperfections all = testing::every_imperfection();
  ASSERT_EQ(all.stamp_resolution_s, 1e-3);
  ASSERT_EQ(all.angle_quantum_deg, 360.0 / kMainCounts);
  ASSERT_EQ(all.position_count_deg, 360.0 / kPositionCounts);
  std::vector<testing::RigRow> rows;
  testing::rig_rows(s, all, testing::RigMotion{}, 7, [&](const testing::RigRow& r) { rows.push_back(r); });

  const std::filesystem::path dir = test::fresh_test_folder("gyrocal-rig-layout");
  write_rig_layout(dir / "rig.csv", rows);
  const test::CliOutcome c = calibrate_in(dir, "rig.csv", scenario_to_toml(s) + kMapping);
  ASSERT_EQ(c.status, 0) << c.err;
  const nlohmann::json j = nlohmann::json::parse(c.out);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    const nlohmann::json& e = j.at("coefficients").at(std::string(kCoefficientNames[k]));
    ASSERT_TRUE(e.at("identifiable").get<bool>()) << kCoefficientNames[k];
    const double value = e.at("value").get<double>(), std = e.at("std").get<double>();
    EXPECT_NEAR(value, s.gyro.values[k], 4.0 * std) << kCoefficientNames[k];
    // A standard uncertainty of the size the white noise allows, not a tiny one on a wrong number: the
    // unmapped rig record (tests/test_reduce.cpp) gives the same order.
    EXPECT_GT(std, 0.0) << kCoefficientNames[k];
  }
  const nlohmann::json& q = j.at("data_quality");
  EXPECT_EQ(q.at("rows_read").get<std::size_t>(), rows.size());
  EXPECT_EQ(q.at("gaps").get<std::size_t>(), 2u);  // the 10 % gap and the clock jump
  EXPECT_GE(q.at("outliers").get<std::size_t>(), 1u);
  EXPECT_EQ(q.at("encoder_glitch_rows").get<std::size_t>(), 1u);
  EXPECT_EQ(q.at("dwells").size(), 8u);
  std::filesystem::remove_all(dir);
}

/// The text `gyrocal init` writes for s, with one line of [reduce] edited as a lab would edit it.
std::string with_reduce_line(const Scenario& s, const std::string& key, const std::string& value) {
  std::string text = scenario_to_toml(s);
  const std::size_t at = text.find("\n" + key + " = ", text.find("\n[reduce]\n"));
  EXPECT_NE(at, std::string::npos) << key;
  if (at == std::string::npos) return text;
  const std::size_t end = text.find('\n', at + 1);
  return text.replace(at + 1, end - at - 1, key + " = " + value);
}

TEST(RigRecord, ARateToleranceSetInTheConfigurationChangesWhatTheReducerAccepts) {
  // The drive turns 0.3 % off its nominal rates: beyond the default rate_tolerance (2e-3), within 5e-3.
  Scenario s = default_scenario();
  s.test.sample_rate_hz = 50.0;
  s.test.revolutions = 8;
  s.test.rates_rad_s = {9.9, 7.0};
  testing::RigImperfections drive;
  drive.rate_offset = 3e-3;
  std::vector<testing::RigRow> rows;
  testing::rig_rows(s, drive, testing::RigMotion{}, 11, [&](const testing::RigRow& r) { rows.push_back(r); });
  const std::filesystem::path dir = test::fresh_test_folder("gyrocal-rig-rate-tolerance");
  {
    std::ofstream out(dir / "rig.csv");
    testing::write_native(out, rows);
  }

  // The default: refused, the reason naming the tolerance and the measured offset.
  const test::CliOutcome refused = calibrate_in(dir, "rig.csv", scenario_to_toml(s));
  EXPECT_NE(refused.status, 0);
  EXPECT_NE(refused.err.find("3.00e-03 (relative) from the planned 9.9 rad/s (rate_tolerance 2e-03)"),
            std::string::npos)
      << refused.err;
  EXPECT_TRUE(refused.out.empty()) << refused.out;

  // [reduce] rate_tolerance = 5e-3: the same record calibrates to the truth within its uncertainties.
  const test::CliOutcome c = calibrate_in(dir, "rig.csv", with_reduce_line(s, "rate_tolerance", "5e-3"));
  ASSERT_EQ(c.status, 0) << c.err;
  const nlohmann::json j = nlohmann::json::parse(c.out);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    const nlohmann::json& e = j.at("coefficients").at(std::string(kCoefficientNames[k]));
    ASSERT_TRUE(e.at("identifiable").get<bool>()) << kCoefficientNames[k];
    EXPECT_NEAR(e.at("value").get<double>(), s.gyro.values[k], 4.0 * e.at("std").get<double>())
        << kCoefficientNames[k];
  }
  // Each dwell measured its rate 0.3 % above the plan's.
  for (const nlohmann::json& d : j.at("data_quality").at("dwells")) {
    const double planned = d.at("rate_rad_s").get<double>(),
                 measured = d.at("measured_rate_rad_s").get<double>();
    EXPECT_NEAR(measured / planned - 1.0, 3e-3, 1e-4) << d.dump();
  }

  std::filesystem::remove_all(dir);
}

TEST(RigRecord, TheReductionMethodComesFromTheConfigurationUnlessTheCommandLineSaysOtherwise) {
  Scenario s = default_scenario();
  s.test.sample_rate_hz = 50.0;
  s.test.revolutions = 8;
  s.test.rates_rad_s = {9.9, 7.0};
  std::vector<testing::RigRow> rows;
  testing::rig_rows(s, testing::RigImperfections{}, testing::RigMotion{}, 5,
                    [&](const testing::RigRow& r) { rows.push_back(r); });
  const std::filesystem::path dir = test::fresh_test_folder("gyrocal-rig-reduction");
  {
    std::ofstream out(dir / "rig.csv");
    testing::write_native(out, rows);
  }
  const auto coefficients = [](const test::CliOutcome& o) {
    EXPECT_EQ(o.status, 0) << o.err;
    return o.status == 0 ? nlohmann::json::parse(o.out).at("coefficients") : nlohmann::json();
  };
  const std::string harmonic = scenario_to_toml(s);
  std::string window = harmonic;
  const std::size_t at = window.find("\nreduction = \"harmonic\"");
  ASSERT_NE(at, std::string::npos) << window;
  window.replace(at + 1, std::string("reduction = \"harmonic\"").size(), "reduction = \"window\"");

  const nlohmann::json by_default = coefficients(calibrate_in(dir, "rig.csv", harmonic));
  const nlohmann::json by_flag = coefficients(calibrate_in(dir, "rig.csv", harmonic, " --reduction window"));
  const nlohmann::json by_config = coefficients(calibrate_in(dir, "rig.csv", window));
  const nlohmann::json overridden =
      coefficients(calibrate_in(dir, "rig.csv", window, " --reduction harmonic"));
  EXPECT_NE(by_flag, by_default);  // the two methods differ on a noisy record
  EXPECT_EQ(by_config, by_flag);
  EXPECT_EQ(overridden, by_default);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace gyrocal
