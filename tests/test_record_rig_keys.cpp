// What a rig's [record] needs beyond columns and units (docs/records.md): an inverted output (a negative
// scale), an output offset, encoder zero offsets, a preamble and a units row to skip, a decimal comma; and
// what the refusal of a record without a usable dwell says when a unit of the mapping is wrong (the time
// step, the rates found, the key to check).
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/model/gyro.hpp"
#include "gyrocal/record/record.hpp"
#include "support/cli_run.hpp"
#include "support/rig_record.hpp"

namespace gyrocal {
namespace {

RecordLayout layout_from(const std::string& toml) {
  return parse_scenario(toml, "rig.toml").record.value();
}

using test::config_error;

TEST(RecordRigKeys, ReadsADecimalCommaAPreambleAUnitsRowOffsetsAndAnInvertedOutput) {
  const RecordLayout layout = layout_from(R"([record]
delimiter = ";"
decimal = ","
skip_rows = 2
units_row = true
time_column = "t"
main_angle_column = "m"
counter_angle_column = "c"
position_angle_column = "p"
output_column = "w"
output_scale_per_deg_h = -2.5
output_offset = 100.0
main_angle_offset_deg = 17.25
counter_angle_offset_deg = -0.5
position_angle_offset_deg = 90.0
)");
  const std::string text =
      "Station 2 export, 2026-11-25\n"  // an uncommented preamble of two lines, one holding the delimiter
      "operator;A. N. Other\n"
      "t;m;c;p;w\n"
      "s;deg;deg;deg;mV\n"  // the units row
      "0,5;20,25;1,5;135;75\n"
      "1;-10;0;90,125;1,25e2\n";
  RecordReader reader = RecordReader::from_string(text, layout, "rig.csv");
  RecordSample s;
  ASSERT_TRUE(reader.next(s));
  EXPECT_EQ(reader.line_number(), 5u);
  EXPECT_EQ(s.time_s, 0.5);
  EXPECT_EQ(s.main_angle_deg, 3.0);       // 20.25 - 17.25
  EXPECT_EQ(s.counter_angle_deg, 2.0);    // 1.5 + 0.5
  EXPECT_EQ(s.position_angle_deg, 45.0);  // 135 - 90
  EXPECT_EQ(s.outputs[0], 10.0);          // (75 - 100) / -2.5
  ASSERT_TRUE(reader.next(s));
  EXPECT_EQ(s.time_s, 1.0);
  EXPECT_EQ(s.main_angle_deg, -27.25);
  EXPECT_EQ(s.position_angle_deg, 0.125);
  EXPECT_EQ(s.outputs[0], -10.0);  // (125 - 100) / -2.5
  EXPECT_FALSE(reader.next(s));

  // A '.' in a record read with a decimal comma is not a number, and the message says which field.
  try {
    RecordReader r = RecordReader::from_string("x\nx\nt;m;c;p;w\nu\n0.5;1;1;1;1\n", layout, "rig.csv");
    r.next(s);
    ADD_FAILURE() << "no refusal";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("rig.csv, line 5: column 1 (t) is '0.5', which is not a number"),
              std::string::npos)
        << e.what();
  }
  // The keys survive the configuration's round trip (what `init` and scenario_to_toml write).
  Scenario sc = default_scenario();
  sc.record = layout;
  EXPECT_EQ(parse_scenario(scenario_to_toml(sc), "rig.toml").record, layout);
}

TEST(RecordRigKeys, RefusesWhatCannotBeReadNamingTheKey) {
  EXPECT_NE(config_error("[record]\noutput_scale_per_deg_h = 0\n")
                .find("record.output_scale_per_deg_h must be a finite non-zero number"),
            std::string::npos);
  EXPECT_NE(config_error("[record]\ndecimal = \",\"\n").find("record.decimal ',' is also record.delimiter"),
            std::string::npos)
      << config_error("[record]\ndecimal = \",\"\n");
  EXPECT_NE(config_error("[record]\ndecimal = \"x\"\n").find("record.decimal must be"), std::string::npos);
  EXPECT_NE(config_error("[record]\nskip_rows = -1\n").find("skip_rows"), std::string::npos);
  EXPECT_NE(config_error("[record]\nmain_angle_offset_deg = nan\n").find("record.main_angle_offset_deg"),
            std::string::npos);
  // A record shorter than its preamble.
  const RecordLayout layout = layout_from("[record]\nskip_rows = 3\n");
  EXPECT_THROW(RecordReader::from_string("a\nb\n", layout, "rig.csv"), Error);
}

// ---- a rig's record, calibrated through the keys ----------------------------------------------------------

constexpr std::int64_t kCounts = 3600;  // 0.1 deg per count
constexpr double kMilliVoltPerDegH = 2.5;
constexpr double kOffsetMilliVolt = 100.0;
constexpr double kMainZeroDeg = 17.2;  // the main encoder reads 17.2 deg at the machine's zero (172 counts)

std::int64_t wrapped_count(double deg, std::int64_t per_rev) {
  const auto c = static_cast<std::int64_t>(std::llround(deg * static_cast<double>(per_rev) / 360.0));
  return ((c % per_rev) + per_rev) % per_rev;
}

Scenario rig_scenario() {
  Scenario s = default_scenario();
  s.test.sample_rate_hz = 50.0;
  s.test.revolutions = 8;
  s.test.rates_rad_s = {9.9, 7.0};
  return s;
}

std::vector<testing::RigRow> rig_rows(const Scenario& s, std::uint64_t seed) {
  std::vector<testing::RigRow> rows;
  testing::rig_rows(s, testing::RigImperfections{}, testing::RigMotion{}, seed,
                    [&](const testing::RigRow& r) { rows.push_back(r); });
  return rows;
}

TEST(RecordRigKeys, AnInvertedOffsetRigRecordWithADecimalCommaCalibratesToTheTruth) {
  const Scenario s = rig_scenario();
  const std::vector<testing::RigRow> rows = rig_rows(s, 21);
  const std::filesystem::path dir = test::fresh_test_folder("gyrocal-rig-keys");
  {
    std::ofstream out(dir / "rig.csv");
    out << "DAQ station 2\nexport of 2026-11-25; channel map v3\n";
    out << "t_ms;gyro_mV;theta_cnt;psi_cnt;beta_cnt\nms;mV;counts;counts;counts\n";
    for (const testing::RigRow& r : rows) {
      // The output inverted (a cable), offset by 100 mV, written with a decimal comma.
      std::string mv = fmt::format("{}", -kMilliVoltPerDegH * r.output + kOffsetMilliVolt);
      for (char& c : mv)
        if (c == '.') c = ',';
      out << std::llround(r.time_s * 1e3) << ';' << mv << ';'
          << wrapped_count(r.main_angle_deg + kMainZeroDeg, kCounts) << ';'
          << wrapped_count(r.counter_angle_deg, kCounts) << ';'
          << wrapped_count(r.position_angle_deg, kCounts) << '\n';
    }
  }
  const std::string mapping = fmt::format(R"(
[record]
delimiter = ";"
decimal = ","
skip_rows = 2
units_row = true
time_column = "t_ms"
time_unit = "ms"
main_angle_column = "theta_cnt"
counter_angle_column = "psi_cnt"
position_angle_column = "beta_cnt"
main_counts_per_revolution = {0}
counter_counts_per_revolution = {0}
position_counts_per_revolution = {0}
output_column = "gyro_mV"
output_scale_per_deg_h = {1}
output_offset = {2}
main_angle_offset_deg = {3}
)",
                                          kCounts, -kMilliVoltPerDegH, kOffsetMilliVolt, kMainZeroDeg);
  const test::CliOutcome c = test::calibrate_in(dir, "rig.csv", scenario_to_toml(s) + mapping);
  ASSERT_EQ(c.status, 0) << c.err;
  const nlohmann::json j = nlohmann::json::parse(c.out);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    const nlohmann::json& e = j.at("coefficients").at(std::string(kCoefficientNames[k]));
    ASSERT_TRUE(e.at("identifiable").get<bool>()) << kCoefficientNames[k];
    const double std = e.at("std").get<double>();
    EXPECT_GT(std, 0.0) << kCoefficientNames[k];
    EXPECT_NEAR(e.at("value").get<double>(), s.gyro.values[k], 4.5 * std) << kCoefficientNames[k];
  }
  // Without the encoder's zero the same record misfits: it is refused, or its std is scaled by the residuals
  // (docs/calibration.md, "When the residuals misfit") and honest again, or it lands off the truth; never a
  // good record's std on a wrong number. The key is what brings the weights' own std back.
  std::string unzeroed = mapping;
  unzeroed.insert(unzeroed.find("main_angle_offset_deg"), "# ");  // the key commented out
  const test::CliOutcome off = test::calibrate_in(dir, "rig.csv", scenario_to_toml(s) + unzeroed);
  double worst_z = 0.0, std_scale = 1.0;
  if (off.status == 0) {
    const nlohmann::json o = nlohmann::json::parse(off.out);
    std_scale = o.at("misfit").at("std_scale").get<double>();
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
      const nlohmann::json& e = o.at("coefficients").at(std::string(kCoefficientNames[k]));
      if (!e.at("identifiable").get<bool>()) continue;
      worst_z = std::max(
          worst_z, std::abs(e.at("value").get<double>() - s.gyro.values[k]) / e.at("std").get<double>());
    }
  }
  EXPECT_TRUE(off.status != 0 || worst_z > 4.5 || std_scale > 1.5) << worst_z << " " << std_scale;
  std::filesystem::remove_all(dir);
}

// ---- unit mistakes in a mapping: the refusal says what the record holds
// ------------------------------------

constexpr std::int64_t kFineCounts = std::int64_t{1} << 20;

TEST(RecordRigKeys, EachUnitMistakeIsNamedByWhatTheRecordHolds) {
  const Scenario s = rig_scenario();
  const std::vector<testing::RigRow> rows = rig_rows(s, 22);
  const std::filesystem::path dir = test::fresh_test_folder("gyrocal-rig-units");
  {
    std::ofstream out(dir / "rig.csv");
    out << "t_ms;gyro;theta;psi;beta\n";
    out.precision(17);
    for (const testing::RigRow& r : rows)
      out << std::llround(r.time_s * 1e3) << ';' << r.output << ';'
          << wrapped_count(r.main_angle_deg, kFineCounts) << ';'
          << wrapped_count(r.counter_angle_deg, kFineCounts) << ';' << fmt::format("{}", r.position_angle_deg)
          << '\n';
  }
  const auto mapping = [](const std::string& time_unit, const std::string& main_counts) {
    return fmt::format(R"(
[record]
delimiter = ";"
time_column = "t_ms"
{}
main_angle_column = "theta"
counter_angle_column = "psi"
position_angle_column = "beta"
{}
counter_counts_per_revolution = {}
output_column = "gyro"
)",
                       time_unit, main_counts, kFineCounts);
  };
  const auto calibrate = [&](const std::string& m) {
    return test::calibrate_in(dir, "rig.csv", scenario_to_toml(s) + m);
  };
  const std::string main_counts = fmt::format("main_counts_per_revolution = {}", kFineCounts);
  // The mapping right: the record calibrates (so each refusal below is its mistake's).
  EXPECT_EQ(calibrate(mapping("time_unit = \"ms\"", main_counts)).status, 0);
  struct Mistake {
    std::string what, mapping;
    std::vector<std::string> said;
  };
  const std::vector<Mistake> mistakes = {
      {"no time_unit: ms read as s",
       mapping("", main_counts),
       {"at a time step of 20 s (median; the plan's sample interval is 0.02 s",
        "the time step is 1000x the planned sample interval: is record.time_unit ms (record.time_unit = "
        "\"ms\", not \"s\")?"}},
      {"us for ms",
       mapping("time_unit = \"us\"", main_counts),
       {"at a time step of 2e-05 s",
        "the time step is 1/1000 of the planned sample interval: is record.time_unit ms (record.time_unit = "
        "\"ms\", not \"us\")?"}},
      {"no main_counts_per_revolution: counts read as degrees",
       mapping("time_unit = \"ms\"", ""),
       {"the main angle reads", "the main angle changes by up to",
        "does it hold encoder counts (record.main_counts_per_revolution, about"}},
      {"2^19 counts for 2^20",
       mapping("time_unit = \"ms\"", "main_counts_per_revolution = 524288"),
       {"Steady runs found: 0 gave a dwell", "the main axis turns at 2x the planned rate (",
        "is record.main_counts_per_revolution = 524288 the encoder's? It reads 2x the angle: an encoder of "
        "about 1048576 (2^20) counts per revolution"}},
  };
  for (const Mistake& m : mistakes) {
    const test::CliOutcome o = calibrate(m.mapping);
    EXPECT_NE(o.status, 0) << m.what;
    EXPECT_NE(o.err.find("the record has no usable dwell"), std::string::npos) << m.what << ": " << o.err;
    for (const std::string& part : m.said)
      EXPECT_NE(o.err.find(part), std::string::npos) << m.what << ": " << o.err;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace gyrocal
