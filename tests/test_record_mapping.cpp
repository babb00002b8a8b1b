// A rig's own record read through the [record] mapping (docs/contract.md, "Records"; docs/records.md): every
// key on a foreign record written here, values against ones computed here by another route, each mistake
// refused with its key and line, and a mapped record calibrating and characterising as the native one does.
#include <gtest/gtest.h>

#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;

std::vector<RecordSample> read_all(const std::string& text, const std::optional<RecordLayout>& layout,
                                   std::size_t chunk_bytes = RecordReader::kDefaultChunkBytes) {
  RecordReader reader = RecordReader::from_string(text, layout, "rig.csv", chunk_bytes);
  std::vector<RecordSample> rows;
  RecordSample sample;
  while (reader.next(sample)) rows.push_back(sample);
  return rows;
}

/// The message of reading `text` through `layout`, or "" when it reads.
std::string read_error(const std::string& text, const std::optional<RecordLayout>& layout) {
  try {
    read_all(text, layout);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

/// The message of parsing a configuration, or "" when it parses.
using test::config_error;

RecordLayout layout_from(const std::string& toml) {
  const Scenario s = parse_scenario(toml, "rig.toml");
  EXPECT_TRUE(s.record.has_value());
  return s.record.value_or(RecordLayout{});
}

__extension__ typedef __int128 Int128;  // exact products of up to 2^85 (GCC and Clang)

/// True when `seconds` is the double nearest to ticks / ticks_per_s (exact integer arithmetic, an oracle
/// independent of the reader's route): |m * per_s - ticks * 2^-e| <= per_s / 2 for seconds = m * 2^e.
bool correctly_rounded(double seconds, std::int64_t ticks, std::int64_t ticks_per_s) {
  int exponent = 0;
  const double fraction = std::frexp(seconds, &exponent);
  const auto mantissa = static_cast<Int128>(std::ldexp(fraction, 53));
  const int e = exponent - 53;
  if (e > 0) return false;  // not reached by the stamps below
  const Int128 difference = mantissa * ticks_per_s - (static_cast<Int128>(ticks) << -e);
  return 2 * (difference < 0 ? -difference : difference) <= ticks_per_s;
}

// ---- every key, on records written here
// ----------------------------------------------------------------------

TEST(RecordMapping, SemicolonMillisecondsWrappedCountsAndMillivolts) {
  const RecordLayout layout = layout_from(R"([record]
delimiter = ";"
time_column = "Zeit"
time_unit = "ms"
main_angle_column = "theta_cnt"
counter_angle_column = "psi_cnt"
position_angle_column = "beta_cnt"
main_counts_per_revolution = 16777216
counter_counts_per_revolution = 65536
position_counts_per_revolution = 1048576
output_column = "U_gyro"
output_scale_per_deg_h = 2.5
)");
  constexpr std::int64_t kMain = 16777216, kCounter = 65536, kPosition = 1048576;
  std::ostringstream text;
  text << std::setprecision(17) << "Zeit;status;theta_cnt;psi_cnt;beta_cnt;U_gyro\n";
  struct Row {
    std::int64_t ms, main, counter, position, output_k;
  };
  std::vector<Row> rows;
  for (std::int64_t i = 0; i < 2000; ++i) {
    Row r;
    r.ms = 1700000000000 + 5 * i + (i % 3);     // Unix-epoch milliseconds, jittered
    r.main = (123456 + i * 1398101) % kMain;    // wrapped counts
    r.counter = -(i * 5461) - 7;                // unwrapped, negative
    r.position = (i < 1000 ? 262144 : 262145);  // a count that toggles
    r.output_k = 1000 - 3 * i;                  // output = k * 0.3125 mV, exact in binary
    rows.push_back(r);
    text << r.ms << ";OK;" << r.main << ";" << r.counter << ";" << r.position << ";"
         << static_cast<double>(r.output_k) * 0.3125 << "\n";
  }
  for (const std::size_t chunk : {RecordReader::kDefaultChunkBytes, std::size_t{7}}) {
    const std::vector<RecordSample> read = read_all(text.str(), layout, chunk);
    ASSERT_EQ(read.size(), rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      ASSERT_TRUE(correctly_rounded(read[i].time_s, r.ms, 1000)) << i;
      // count * 360 / counts, rounded once (long double holds count * 360 exactly).
      const auto degrees = [](std::int64_t count, std::int64_t per_rev) {
        return static_cast<double>(static_cast<long double>(count) * 360.0L /
                                   static_cast<long double>(per_rev));
      };
      ASSERT_EQ(read[i].main_angle_deg, degrees(r.main, kMain)) << i;
      ASSERT_EQ(read[i].counter_angle_deg, degrees(r.counter, kCounter)) << i;
      ASSERT_EQ(read[i].position_angle_deg, degrees(r.position, kPosition)) << i;
      // 0.3125 mV / (2.5 mV per deg/h) = 0.125 deg/h per k, exactly.
      ASSERT_EQ(read[i].outputs[0], static_cast<double>(r.output_k) * 0.125) << i;
    }
  }
}

TEST(RecordMapping, NanosecondStampsKeepTheirDigits) {
  const RecordLayout layout = layout_from("[record]\ntime_unit = \"ns\"\n");
  std::ostringstream text;
  text << "time_s,main_angle_deg,counter_angle_deg,position_angle_deg,gyro_deg_h\n";
  std::vector<std::int64_t> stamps;
  for (std::int64_t i = 0; i < 3000; ++i) {
    stamps.push_back(1700000000123456789 + i * 4999937);  // 19 digits: beyond a double's 2^53
    text << stamps.back() << ",0,0,0,0\n";
  }
  const std::vector<RecordSample> read = read_all(text.str(), layout);
  ASSERT_EQ(read.size(), stamps.size());
  int naive_differs = 0;
  for (std::size_t i = 0; i < stamps.size(); ++i) {
    ASSERT_TRUE(correctly_rounded(read[i].time_s, stamps[i], 1000000000)) << stamps[i];
    // The route that parses the stamp as a double first loses digits here (the test's own check that these
    // stamps tell the two routes apart).
    naive_differs += static_cast<double>(stamps[i]) / 1e9 != read[i].time_s;
  }
  EXPECT_GT(naive_differs, 0);
}

TEST(RecordMapping, WhitespaceMicrosecondsRadiansAnyOrderAndSkippedColumns) {
  const RecordLayout layout = layout_from(R"([record]
delimiter = " "
comment = "%"
time_column = "t_us"
time_unit = "us"
main_angle_column = "theta"
counter_angle_column = "psi"
position_angle_column = "beta"
angle_unit = "rad"
output_column = "w"
)");
  std::ostringstream text;
  text << "% rig 7 = bench B\n%a comment\n\n  w \t beta\tnote   psi theta t_us  \n";
  std::vector<double> deg;
  for (int i = 0; i < 500; ++i) {
    const double d = -720.0 + 3.7 * i;
    deg.push_back(d);
    char rad[64];
    std::snprintf(rad, sizeof rad, "%.17Lg",
                  static_cast<long double>(d) * 3.14159265358979323846264338327950288L / 180.0L);
    text << (i % 2 ? "\t" : "") << 0.25 * i << "  " << rad << "\tx" << i << " " << rad << "\t\t" << rad << " "
         << 1000000 + 2500 * i + 1 << (i % 3 ? " " : "") << "\n";
    if (i == 250) text << "% a comment among the rows\n";
  }
  RecordReader reader = RecordReader::from_string(text.str(), layout, "rig.txt");
  ASSERT_EQ(reader.metadata().size(), 1u);
  EXPECT_EQ(reader.metadata()[0].first, "rig 7");
  EXPECT_EQ(reader.metadata()[0].second, "bench B");
  RecordSample s;
  for (int i = 0; i < 500; ++i) {
    ASSERT_TRUE(reader.next(s)) << i;
    ASSERT_TRUE(correctly_rounded(s.time_s, 1000000 + 2500 * i + 1, 1000000)) << i;
    for (double angle : {s.main_angle_deg, s.counter_angle_deg, s.position_angle_deg}) {
      ASSERT_NEAR(angle, deg[static_cast<std::size_t>(i)],
                  1e-13 * std::abs(deg[static_cast<std::size_t>(i)]) + 1e-15);
    }
    ASSERT_EQ(s.outputs[0], 0.25 * i);
  }
  EXPECT_FALSE(reader.next(s));
}

TEST(RecordMapping, TabsQuotedNamesAndTheNativeMagicLineAndMetadata) {
  const RecordLayout layout = layout_from("[record]\ndelimiter = \"\\t\"\ntime_column = \"time s\"\n");
  const std::string text =
      "# gyrocal-record 1\n# radius_m = 1.5\n\"time s\"\t\"main_angle_deg\"\tcounter_angle_deg\t"
      "position_angle_deg\tgyro_deg_h\n0.5\t1\t2\t3\t4\n1.5\t 5 \t6\t7\t8\n";
  RecordReader reader = RecordReader::from_string(text, layout);
  ASSERT_EQ(reader.metadata().size(), 1u);
  EXPECT_EQ(reader.metadata()[0].second, "1.5");
  RecordSample s;
  ASSERT_TRUE(reader.next(s));
  EXPECT_EQ(s.time_s, 0.5);
  ASSERT_TRUE(reader.next(s));
  EXPECT_EQ(s.main_angle_deg, 5.0);
  EXPECT_EQ(s.outputs[0], 8.0);
  // An empty field between two tabs is a field, not a longer delimiter.
  const std::string message = read_error(
      "time s\tmain_angle_deg\tcounter_angle_deg\tposition_angle_deg\tgyro_deg_h\n0\t1\t\t3\t4\n", layout);
  EXPECT_NE(message.find("rig.csv, line 2: column 3 (counter_angle_deg) is empty"), std::string::npos)
      << message;
}

TEST(RecordMapping, AnEmptySectionReadsGyrocalsColumnsByNameWithoutTheMagicLine) {
  const Scenario with = parse_scenario("[record]\n", "rig.toml");
  ASSERT_TRUE(with.record.has_value());
  EXPECT_EQ(*with.record, RecordLayout{});
  EXPECT_FALSE(parse_scenario("", "rig.toml").record.has_value());
  const std::string text =
      "gyro_deg_h,time_s,position_angle_deg,counter_angle_deg,main_angle_deg,t_c\n4,0,3,2,1,20\n";
  const std::vector<RecordSample> rows = read_all(text, with.record);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].main_angle_deg, 1.0);
  EXPECT_EQ(rows[0].counter_angle_deg, 2.0);
  EXPECT_EQ(rows[0].position_angle_deg, 3.0);
  EXPECT_EQ(rows[0].outputs[0], 4.0);
  // Without a [record] section the magic line is still required.
  EXPECT_NE(read_error(text, std::nullopt).find("this is not a gyrocal record"), std::string::npos);
}

TEST(RecordMapping, AbsentAngleColumnsReadAsNaNAndCalibrationRefusesThem) {
  const RecordLayout layout =
      layout_from("[record]\nmain_angle_column = \"\"\ncounter_angle_column = \"\"\ntime_column = \"t\"\n");
  const std::vector<RecordSample> rows = read_all("t,gyro_deg_h,position_angle_deg\n0,1,2\n1,3,4\n", layout);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_TRUE(std::isnan(rows[1].main_angle_deg));
  EXPECT_TRUE(std::isnan(rows[1].counter_angle_deg));
  EXPECT_EQ(rows[1].position_angle_deg, 4.0);
  EXPECT_EQ(rows[1].outputs[0], 3.0);
  const Scenario s = default_scenario();
  try {
    calibrate_record("static.csv", s.model(), s.test, CalibrationOptions{}, layout);
    FAIL() << "a layout without angles calibrated";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("record.main_angle_column, record.counter_angle_column are empty"),
              std::string::npos)
        << e.what();
  }
}

// ---- mistakes
// ------------------------------------------------------------------------------------------------

TEST(RecordMapping, HeaderMismatchesNameTheKeyTheFileTheLineAndTheColumnsFound) {
  const RecordLayout semicolon = layout_from("[record]\ndelimiter = \";\"\ntime_column = \"Zeit\"\n");
  struct Case {
    std::string text;
    std::optional<RecordLayout> layout;
    std::vector<std::string> parts;
  };
  const std::string header = "# note\nZeit;main_angle_deg;counter_angle_deg;position_angle_deg;Drehrate\n";
  const std::vector<Case> cases = {
      {header + "0;0;0;0;0\n",
       semicolon,
       {"rig.csv, line 2: record.output_column = 'gyro_deg_h' is not a column of the header line "
        "'Zeit;main_angle_deg;counter_angle_deg;position_angle_deg;Drehrate'",
        "the columns found are 'Zeit', 'main_angle_deg', 'counter_angle_deg', 'position_angle_deg', "
        "'Drehrate'"}},
      {"Zeit,main_angle_deg,counter_angle_deg,position_angle_deg,gyro_deg_h\n",
       semicolon,
       {"rig.csv, line 1: record.delimiter ';' splits nothing in the header line 'Zeit,main_angle_deg,"}},
      {"Zeit;gyro_deg_h;main_angle_deg;counter_angle_deg;position_angle_deg;Zeit\n",
       semicolon,
       {"rig.csv, line 1: the header line",
        "names 'Zeit' twice (columns 1 and 6), so record.time_column is "
        "ambiguous"}},
      {"1;2;3;4;5\n", semicolon, {"rig.csv, line 1: the header line is missing"}},
      {"", semicolon, {"rig.csv is empty"}},
      {"# only = metadata\n", semicolon, {"rig.csv, line 1: the record ends without a header line"}},
      {"Zeit;gyro_deg_h;main_angle_deg;counter_angle_deg;position_angle_deg\n1;2;3;4\n",
       semicolon,
       {"rig.csv, line 2: the row has 4 fields but the header has 5 columns"}},
      {"Zeit;gyro_deg_h;main_angle_deg;counter_angle_deg;position_angle_deg\n1;x;3;4;5\n",
       semicolon,
       {"rig.csv, line 2: column 2 (gyro_deg_h) is 'x', which is not a number"}},
      {"Zeit;gyro_deg_h;main_angle_deg;counter_angle_deg;position_angle_deg\n2;1;3;4;5\n2;1;3;4;5\n",
       semicolon,
       {"rig.csv, line 3: the time (Zeit, 2 s) does not increase (the previous row has 2 s)"}},
  };
  for (const Case& c : cases) {
    const std::string message = read_error(c.text, c.layout);
    for (const std::string& part : c.parts) EXPECT_NE(message.find(part), std::string::npos) << message;
  }
}

TEST(RecordMapping, ConfigurationMistakesNameTheKeyAndItsLine) {
  struct Case {
    std::string toml, expected;
  };
  const std::vector<Case> cases = {
      {"[record]\ntime_unit = \"sec\"",
       "rig.toml, line 2: record.time_unit must be s, ms, us or ns, not \"sec\""},
      {"[record]\n\nangle_unit = \"grad\"", "rig.toml, line 3: record.angle_unit must be deg or rad"},
      {"[record]\ndelimiter = \";;\"", "rig.toml, line 2: record.delimiter must be one character"},
      {"[record]\ndelimiter = \"\"", "rig.toml, line 2: record.delimiter must be one character"},
      {"[record]\ndelimiter = \"5\"", "rig.toml, line 2: record.delimiter '5' cannot separate numbers"},
      {"[record]\ndelimiter = \".\"", "rig.toml, line 2: record.delimiter '.' cannot separate numbers"},
      {"[record]\noutput_column = \"w\"\nmain_angle_column = \"w\"",
       "rig.toml, line 2: record.main_angle_column and record.output_column both name the column 'w'"},
      {"[record]\ncounter_angle_column = \"time_s\"",
       "rig.toml, line 2: record.time_column and record.counter_angle_column both name the column 'time_s'"},
      // A negative scale reads an inverted output (tests/test_record_rig_keys.cpp); zero reads nothing.
      {"[record]\noutput_scale_per_deg_h = 0",
       "rig.toml, line 2: record.output_scale_per_deg_h must be a finite non-zero number"},
      {"[record]\noutput_scale_per_deg_h = nan", "record.output_scale_per_deg_h must be a finite"},
      {"[record]\noutput_scale_per_deg_h = inf", "record.output_scale_per_deg_h must be a finite"},
      {"[record]\nmain_counts_per_revolution = 1",
       "rig.toml, line 2: record.main_counts_per_revolution must be 0 (the column holds angles in "
       "angle_unit) "
       "or an integer >= 2 (encoder counts per revolution), not 1"},
      {"[record]\ncounter_counts_per_revolution = -4096",
       "rig.toml, line 2: record.counter_counts_per_revolution must be 0"},
      {"[record]\nposition_counts_per_revolution = 4096.5",
       "rig.toml, line 2: record.position_counts_per_revolution must be an integer, not a floating-point "
       "number"},
      {"[record]\ntime_column = \"\"", "rig.toml, line 2: record.time_column must name a column"},
      {"[record]\noutput_column = \"\"", "rig.toml, line 2: record.output_column must name a column"},
      {"[record]\ndelimiter = \";\"\ntime_column = \"a;b\"",
       "rig.toml, line 3: record.time_column = 'a;b' holds ';'"},
      {"[record]\ncomment = \"-\"", "rig.toml, line 2: record.comment '-' begins with '-'"},
      {"[record]\ntime_unit = 1000", "rig.toml, line 2: record.time_unit must be a string, not an integer"},
      {"[record]\ntime_colum = \"t\"", "rig.toml, line 2: unknown key record.time_colum"},
  };
  for (const Case& c : cases) {
    const std::string message = config_error(c.toml);
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.toml << "\n  gave: " << message;
  }
}

TEST(RecordMapping, SectionRoundTripsAndInitDocumentsEveryKey) {
  Scenario s = default_scenario();
  RecordLayout l;
  l.delimiter = '\t';
  l.comment = "//";
  l.time_column = "Zeit [s]";
  l.time_unit = TimeUnit::kNanoseconds;
  l.main_angle_column = "";
  l.angle_unit = AngleUnit::kRadians;
  l.counter_counts_per_revolution = 1 << 20;
  l.output_scale_per_deg_h = 0.1;
  s.record = l;
  const Scenario back = parse_scenario(scenario_to_toml(s), "back.toml");
  ASSERT_TRUE(back.record.has_value());
  EXPECT_EQ(*back.record, l);
  // The default scenario's file documents the section commented out: every key with its default, and reads
  // back without one.
  const std::string init = scenario_to_toml(default_scenario());
  EXPECT_FALSE(parse_scenario(init, "init.toml").record.has_value());
  for (const char* line :
       {"# [record]", "# delimiter = \",\"", "# comment = \"#\"", "# time_column = \"time_s\"",
        "# time_unit = \"s\"", "# main_angle_column = \"main_angle_deg\"",
        "# counter_angle_column = \"counter_angle_deg\"", "# position_angle_column = \"position_angle_deg\"",
        "# angle_unit = \"deg\"", "# main_counts_per_revolution = 0", "# counter_counts_per_revolution = 0",
        "# position_counts_per_revolution = 0", "# output_column = \"gyro_deg_h\"",
        "# output_scale_per_deg_h = 1.0"}) {
    EXPECT_NE(init.find(line), std::string::npos) << line;
  }
  // Uncommented, the documented section is the default layout.
  std::string uncommented;
  std::istringstream lines(init.substr(init.find("# [record]")));
  for (std::string line; std::getline(lines, line);) uncommented += line.substr(2) + "\n";
  const Scenario documented = parse_scenario(uncommented, "uncommented.toml");
  ASSERT_TRUE(documented.record.has_value());
  EXPECT_EQ(*documented.record, RecordLayout{});
}

// ---- a mapped record of a simulated test
// -----------------------------------------------------------------------

/// The short test of the command-line tests, with its noise.
Scenario short_scenario() {
  return parse_scenario(test::short_test_toml(), "short.toml");
}

constexpr std::int64_t kCountsPerRev = std::int64_t{1} << 24;
constexpr double kMillivoltsPerDegH = 2.5;

/// `native` rewritten as a rig would: ';' between fields, integer ms stamps, the angles as 2^24 counts a
/// revolution (main wrapped, the others not), the output in mV at 2.5 mV per deg/h, columns in another order.
std::string foreign_layout(const std::string& native) {
  RecordReader reader = RecordReader::from_string(native);
  std::ostringstream out;
  out << "Kommentar: Pruefstand 2\nU_mV;t_ms;beta_cnt;theta_cnt;psi_cnt\n";
  RecordSample s;
  char line[256];
  const auto counts = [](double deg) {
    return static_cast<long long>(std::llround(deg / 360.0 * kCountsPerRev));
  };
  while (reader.next(s)) {
    std::snprintf(line, sizeof line, "%.17g;%lld;%lld;%lld;%lld\n", s.outputs[0] * kMillivoltsPerDegH,
                  static_cast<long long>(std::llround(s.time_s * 1000.0)), counts(s.position_angle_deg),
                  counts(s.main_angle_deg) % kCountsPerRev, counts(s.counter_angle_deg));
    out << line;
  }
  return out.str();
}

constexpr const char* kForeignToml = R"([record]
delimiter = ";"
comment = "Kommentar"
time_column = "t_ms"
time_unit = "ms"
main_angle_column = "theta_cnt"
counter_angle_column = "psi_cnt"
position_angle_column = "beta_cnt"
main_counts_per_revolution = 16777216
counter_counts_per_revolution = 16777216
position_counts_per_revolution = 16777216
output_column = "U_mV"
output_scale_per_deg_h = 2.5
)";

struct TestFiles {
  fs::path dir, native, foreign, config;
};

TestFiles write_test_files(const std::string& prefix) {
  TestFiles f;
  f.dir = test::fresh_test_folder(prefix);
  f.native = f.dir / "native.csv";
  f.foreign = f.dir / "foreign.csv";
  f.config = f.dir / "rig.toml";
  std::ostringstream native;
  simulate_record(short_scenario(), SimulationOptions{}, native);
  std::ofstream(f.native) << native.str();
  std::ofstream(f.foreign) << foreign_layout(native.str());
  std::ofstream(f.config) << test::short_test_toml() << "\n" << kForeignToml;
  return f;
}

TEST(RecordMapping, AMappedForeignRecordCalibratesAsTheNativeOne) {
  const TestFiles f = write_test_files("gyrocal-mapping");
  const Scenario s = parse_scenario(test::slurp(f.config), f.config.string());
  ASSERT_TRUE(s.record.has_value());
  const CalibrationResult native =
      calibrate_record(f.native.string(), s.model(), s.test, CalibrationOptions{});
  const CalibrationResult foreign =
      calibrate_record(f.foreign.string(), s.model(), s.test, CalibrationOptions{}, s.record);
  ASSERT_EQ(native.positions.size(), foreign.positions.size());
  for (std::size_t i = 0; i < kNumGyroCoefficients; ++i) {
    const CoefficientEstimate& a = native.coefficients[i];
    const CoefficientEstimate& b = foreign.coefficients[i];
    ASSERT_EQ(a.identifiable, b.identifiable) << kCoefficientNames[i];
    if (!a.identifiable) continue;
    // The foreign layout rounds the angles to 2^-24 revolution (2e-5 deg) and the output through mV: the
    // estimates agree far within their uncertainty (1 % of it).
    EXPECT_NEAR(b.value, a.value, 0.01 * a.std) << kCoefficientNames[i];
    EXPECT_NEAR(b.std, a.std, 0.01 * a.std) << kCoefficientNames[i];
  }
  fs::remove_all(f.dir);
}

TEST(RecordMapping, TheCommandLineReadsAMappedRecordForNoiseAndCalibrate) {
  const TestFiles f = write_test_files("gyrocal-mapping-cli");
  const test::CliOutcome refused = test::run_cli("noise " + f.foreign.string() + " --json -", f.dir);
  EXPECT_NE(refused.status, 0);
  EXPECT_NE(refused.err.find("this is not a gyrocal record"), std::string::npos) << refused.err;

  // The simulated record spins: noise refuses it, natively and mapped, naming the motion (docs/interface.md).
  const test::CliOutcome spinning = test::run_cli("noise " + f.native.string() + " --json -", f.dir);
  const test::CliOutcome spinning_mapped =
      test::run_cli("noise " + f.foreign.string() + " --config " + f.config.string() + " --json -", f.dir);
  for (const test::CliOutcome* o : {&spinning, &spinning_mapped}) {
    EXPECT_NE(o->status, 0);
    EXPECT_NE(o->err.find("the record is not static: the main axis turns at"), std::string::npos) << o->err;
  }

  // noise needs only the time and the output: layouts without angle columns read the output as it is, the
  // native record's and the mapped one's alike.
  std::ofstream(f.dir / "native_output_only.toml")
      << "[record]\nmain_angle_column = \"\"\ncounter_angle_column = \"\"\nposition_angle_column = \"\"\n";
  std::ofstream(f.dir / "output_only.toml")
      << "[record]\ndelimiter = \";\"\ncomment = \"Kommentar\"\ntime_column = \"t_ms\"\ntime_unit = \"ms\"\n"
         "main_angle_column = \"\"\ncounter_angle_column = \"\"\nposition_angle_column = \"\"\n"
         "output_column = \"U_mV\"\noutput_scale_per_deg_h = 2.5\n";
  const test::CliOutcome native =
      test::run_cli("noise " + f.native.string() + " --config " +
                        (f.dir / "native_output_only.toml").string() + " --json -",
                    f.dir);
  const test::CliOutcome output_only = test::run_cli(
      "noise " + f.foreign.string() + " --config " + (f.dir / "output_only.toml").string() + " --json -",
      f.dir);
  ASSERT_EQ(native.status, 0) << native.err;
  ASSERT_EQ(output_only.status, 0) << output_only.err;
  const auto a = nlohmann::json::parse(native.out), b = nlohmann::json::parse(output_only.out);
  EXPECT_EQ(a["samples"], b["samples"]);
  ASSERT_EQ(a["allan"].size(), b["allan"].size());
  ASSERT_GT(a["allan"].size(), 4u);
  for (std::size_t i = 0; i < a["allan"].size(); ++i) {
    // The output passed through mV; its Allan deviation agrees to rounding.
    EXPECT_NEAR(b["allan"][i]["adev"].get<double>(), a["allan"][i]["adev"].get<double>(),
                1e-9 * a["allan"][i]["adev"].get<double>());
  }
  const test::CliOutcome no_angles = test::run_cli(
      "calibrate " + f.foreign.string() + " --config " + (f.dir / "output_only.toml").string(), f.dir);
  EXPECT_NE(no_angles.status, 0);
  EXPECT_NE(no_angles.err.find("record.main_angle_column, record.counter_angle_column, "
                               "record.position_angle_column are empty"),
            std::string::npos)
      << no_angles.err;

  const test::CliOutcome calibrated = test::run_cli(
      "calibrate " + f.foreign.string() + " --config " + f.config.string() + " --json -", f.dir);
  ASSERT_EQ(calibrated.status, 0) << calibrated.err;
  EXPECT_TRUE(nlohmann::json::parse(calibrated.out)["coefficients"]["dI"]["identifiable"].get<bool>());
  fs::remove_all(f.dir);
}

}  // namespace
}  // namespace gyrocal
