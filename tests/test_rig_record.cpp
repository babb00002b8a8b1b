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
    out << std::llround(r.time_s * 1e3) << ';' << r.gyro_deg_h * kMilliVoltPerDegH << ';'
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
  {
    std::ofstream toml(dir / "rig.toml");
    toml << scenario_to_toml(s) << kMapping;
  }
  const test::CliOutcome c = test::run_cli(
      "calibrate " + (dir / "rig.csv").string() + " --config " + (dir / "rig.toml").string() + " --json -",
      dir);
  ASSERT_EQ(c.status, 0) << c.err;
  const nlohmann::json j = nlohmann::json::parse(c.out);
  for (std::size_t k = 0; k < kNumCoefficients; ++k) {
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

}  // namespace
}  // namespace gyrocal
