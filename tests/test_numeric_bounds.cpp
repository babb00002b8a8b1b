// Values at the edges of a double's range (issue 29, D13 and D14): an output whose square overflows, an
// encoder reading no encoder writes, a configuration value whose products overflow the model, outputs in the
// subnormal range. Each is refused naming its cause and place, or counted where a rig's glitch belongs.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/scenario_options.hpp"
#include "gyrocal/plan/timeline.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// The message `f()` throws gyrocal::Error with; "" if it does not throw.
template <class F>
std::string refusal(F f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// ---- wrap_deg_quick (D14) --------------------------------------------------------------------------------

TEST(WrapDegQuick, MatchesRemainderAtEveryMagnitude) {
  // Every finite input: std::remainder's value, but for exactly +-180, whose sign may differ.
  std::mt19937_64 random(29);
  std::uniform_real_distribution<double> mantissa(1.0, 10.0);
  std::size_t wrong = 0;
  std::string first;
  for (int exponent = -5; exponent <= 307; ++exponent) {
    for (int k = 0; k < 400; ++k) {
      for (const double sign : {1.0, -1.0}) {
        const double a = sign * mantissa(random) * std::pow(10.0, exponent);
        if (!std::isfinite(a)) continue;
        const double expected = std::remainder(a, 360.0), got = wrap_deg_quick(a);
        const bool same = std::abs(expected) == 180.0 ? std::abs(got) == 180.0 : got == expected;
        if (!same && wrong++ == 0) first = fmt::format("{:.17g}: {} for remainder's {}", a, got, expected);
      }
    }
  }
  // The neighbours of the powers of two where the quick route changes (2^46, 2^50, 2^53 turns).
  for (int e = 40; e <= 70; ++e) {
    const double edge = std::ldexp(360.0, e);
    for (double a = std::nextafter(edge, 0.0), n = 0; n < 8; a = std::nextafter(a, 2 * edge), ++n) {
      const double expected = std::remainder(a, 360.0), got = wrap_deg_quick(a);
      if (!(got == expected || (std::abs(expected) == 180.0 && std::abs(got) == 180.0)) && wrong++ == 0)
        first = fmt::format("{:.17g}: {} for remainder's {}", a, got, expected);
    }
  }
  EXPECT_EQ(wrong, 0u) << "first: " << first;
  EXPECT_EQ(wrap_deg_quick(std::numeric_limits<double>::max()),
            std::remainder(std::numeric_limits<double>::max(), 360.0));
  EXPECT_TRUE(std::isnan(wrap_deg_quick(std::numeric_limits<double>::infinity())));
  EXPECT_TRUE(std::isnan(wrap_deg_quick(std::numeric_limits<double>::quiet_NaN())));
}

// ---- Encoder readings no encoder writes (D14)
// --------------------------------------------------------------

/// A small test: the default scenario at 50 Hz, 20 revolutions a dwell.
Scenario small_test() {
  Scenario s = default_scenario();
  s.test.sample_rate_hz = 50.0;
  s.test.revolutions = 20;
  return s;
}

std::vector<RecordSample> record_of(const Scenario& s) {
  std::vector<RecordSample> rows;
  SimulationOptions so;
  so.seed = 7;
  simulate(s, so, [&](const RecordSample& x) { rows.push_back(x); });
  return rows;
}

Reduction reduce_rows(const Scenario& s, const std::vector<RecordSample>& rows) {
  Reducer reducer(s.test, ReduceOptions{}, "bad.csv", s.centrifuge.rate_rad_s);
  for (const RecordSample& x : rows) reducer.push(x);
  return reducer.finish();
}

/// The index of the first row in the middle of the second dwell's measured part.
std::size_t row_inside_second_dwell(const Scenario& s, const std::vector<RecordSample>& rows) {
  const Timeline tl = make_timeline(s.test, s.model());
  const MeasurementInterval& m = tl.measurements.at(1);
  const double t = 0.5 * (m.start_s + m.end_s);
  std::size_t i = 0;
  while (i < rows.size() && rows[i].time_s < t) ++i;
  return i;
}

double& angle_of(RecordSample& x, int column) {
  return column == 0 ? x.main_angle_deg : column == 1 ? x.counter_angle_deg : x.position_angle_deg;
}

TEST(EncoderBounds, AReadingBeyondAnyEncodersRangeIsAGlitch) {
  // Two rows (up to reduce.encoder_glitch_rows = 3 end no dwell) whose main, counter or position angle reads
  // 1e20, -1e20 or 1e308 deg inside a dwell: dropped and counted as encoder glitches, the dwells as the clean
  // record's. wrap_deg_quick gave 0 for such a reading, which then lay exactly on the predicted line.
  const Scenario s = small_test();
  const std::vector<RecordSample> clean = record_of(s);
  const Reduction ref = reduce_rows(s, clean);
  ASSERT_EQ(ref.encoder_glitch_rows, 0u);
  const std::size_t at = row_inside_second_dwell(s, clean);
  for (int column = 0; column < 3; ++column) {
    for (const double value : {1e20, -1e20, 1e308, 2e10}) {
      std::vector<RecordSample> rows = clean;
      angle_of(rows[at], column) = value;
      angle_of(rows[at + 1], column) = value;
      const Reduction r = reduce_rows(s, rows);
      const std::string tag = fmt::format("column {}, {}", column, value);
      EXPECT_EQ(r.encoder_glitch_rows, 2u) << tag;
      EXPECT_EQ(r.samples_used, ref.samples_used - 2) << tag;
      ASSERT_EQ(r.dwells.size(), ref.dwells.size()) << tag;
    }
  }
}

TEST(EncoderBounds, AColumnOfThemEndsTheDwellNamingTheReading) {
  // 50 rows of main_angle_deg = 1e308 inside a dwell (a dead encoder for a second): more than
  // encoder_glitch_rows, so the dwell ends there, the reason naming the reading; none of them is used.
  const Scenario s = small_test();
  const std::vector<RecordSample> clean = record_of(s);
  const Reduction ref = reduce_rows(s, clean);
  const std::size_t at = row_inside_second_dwell(s, clean);
  std::vector<RecordSample> rows = clean;
  for (std::size_t i = at; i < at + 50; ++i) rows[i].main_angle_deg = 1e308;
  Reduction r;
  const std::string refused = refusal([&] { r = reduce_rows(s, rows); });
  if (!refused.empty()) {
    // The dwell cut in two may be too short: its refusal names the reading.
    EXPECT_TRUE(contains(refused, "1e+308")) << refused;
    return;
  }
  EXPECT_LE(r.samples_used, ref.samples_used - 50);
  bool named = false;
  for (const Dwell& d : r.dwells) named = named || contains(d.quality.ended, "1e+308");
  for (const RejectedRun& x : r.rejected) named = named || contains(x.reason, "1e+308");
  EXPECT_TRUE(named) << "no dwell or rejected run names the reading";
}

// ---- Outputs whose square overflows (D13)
// ------------------------------------------------------------------

constexpr const char* kHeader = "time_s,main_angle_deg,counter_angle_deg,position_angle_deg,gyro_deg_h";

/// A record of `rows` rows with `output` on row `at` (0-based; its line is at + 3) and 1.5 elsewhere.
std::string record_text(int rows, int at, const std::string& output) {
  std::string text = std::string("# gyrocal-record 1\n") + kHeader + "\n";
  for (int i = 0; i < rows; ++i)
    text += fmt::format("{},{},0,0,{}\n", 0.01 * i, 5.0 * i, i == at ? output : "1.5");
  return text;
}

std::string read_all(RecordReader reader) {
  RecordSample x;
  return refusal([&] {
    while (reader.next(x)) {
    }
  });
}

TEST(OutputBounds, TheReaderRefusesAnOutputBeyondTheBoundNamingLineAndColumn) {
  const std::pair<std::string, std::string> outputs[] = {
      {"1e200", "1e+200"}, {"-1e308", "-1e+308"}, {"1.0000001e50", "1.0000001e+50"}, {"2e51", "2e+51"}};
  for (const auto& [output, read] : outputs) {
    const std::string m = read_all(RecordReader::from_string(record_text(20, 10, output), "rec.csv"));
    EXPECT_TRUE(contains(m, "rec.csv, line 13")) << m;
    EXPECT_TRUE(contains(m, "column 5 (gyro_deg_h) is " + read)) << m;
    EXPECT_TRUE(contains(m, "1e+50")) << m;
  }
  // At the bound and below: read.
  for (const std::string output : {"1e50", "-1e50", "3.5e-299", "0"})
    EXPECT_EQ(read_all(RecordReader::from_string(record_text(20, 10, output), "rec.csv")), "") << output;
}

TEST(OutputBounds, ARecordOfTheOutputAloneAndALayoutAreBoundedToo) {
  // time_s,gyro_deg_h: column 2.
  std::string lone = "# gyrocal-record 1\ntime_s,gyro_deg_h\n";
  for (int i = 0; i < 20; ++i) lone += fmt::format("{},{}\n", 0.01 * i, i == 4 ? "1e308" : "0.5");
  std::string m = read_all(RecordReader::from_string(lone, "lone.csv"));
  EXPECT_TRUE(contains(m, "lone.csv, line 7")) << m;
  EXPECT_TRUE(contains(m, "column 2 (gyro_deg_h)")) << m;
  // A layout whose scale makes a plain field huge: the message names the scale's key.
  RecordLayout layout;
  layout.delimiter = ';';
  layout.output_column = "U_mV";
  layout.output_scale_per_deg_h = 1e-60;
  std::string rig = "time_s;main_angle_deg;counter_angle_deg;position_angle_deg;U_mV\n";
  for (int i = 0; i < 20; ++i) rig += fmt::format("{};{};0;0;{}\n", 0.01 * i, 5.0 * i, i == 2 ? "250" : "0");
  m = read_all(RecordReader::from_string(rig, layout, "rig.csv"));
  EXPECT_TRUE(contains(m, "rig.csv, line 4")) << m;
  EXPECT_TRUE(contains(m, "column 5 (U_mV)")) << m;
  EXPECT_TRUE(contains(m, "record.output_scale_per_deg_h")) << m;
}

TEST(OutputBounds, CalibrateAndNoiseRefuseTheSampleNamingLineAndColumnAndWriteNothing) {
  const fs::path dir = test::fresh_test_folder("gyrocal-bounds");
  // A record whose outputs are all 1e200 (the probe's: "10 complete revolutions, too few ... needs at least
  // 3").
  const Scenario s = small_test();
  {
    std::ofstream out(dir / "big.csv");
    RecordWriter writer(out, {}, {});
    for (RecordSample x : record_of(s)) {
      x.outputs[0] = 1e200;
      writer.write(x);
    }
    writer.finish();
    std::ofstream(dir / "s.toml") << scenario_to_toml(s);
  }
  test::CliOutcome o =
      test::run_cli(fmt::format("calibrate {} --config {} --json {}", (dir / "big.csv").string(),
                                (dir / "s.toml").string(), (dir / "r.json").string()),
                    dir);
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_TRUE(contains(o.err, "big.csv, line ")) << o.err;
  EXPECT_TRUE(contains(o.err, "column 5 (gyro_deg_h)")) << o.err;
  EXPECT_FALSE(contains(o.err, "too few")) << o.err;
  EXPECT_FALSE(fs::exists(dir / "r.json"));
  // noise: one 1e308 sample among 4000 of white noise ("no combination of noise terms fits").
  {
    std::ofstream out(dir / "static.csv");
    out << "# gyrocal-record 1\ntime_s,gyro_deg_h\n";
    std::mt19937_64 random(3);
    std::normal_distribution<double> white(0.0, 1.0);
    for (int i = 0; i < 4000; ++i)
      out << fmt::format("{},{}\n", 0.01 * i,
                         i == 1234 ? std::string("1e308") : fmt::format("{}", white(random)));
  }
  o = test::run_cli(
      fmt::format("noise {} --json {}", (dir / "static.csv").string(), (dir / "n.json").string()), dir);
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_TRUE(contains(o.err, "static.csv, line 1237")) << o.err;
  EXPECT_TRUE(contains(o.err, "column 2 (gyro_deg_h)")) << o.err;
  EXPECT_FALSE(fs::exists(dir / "n.json"));
  fs::remove_all(dir);
}

TEST(OutputBounds, TheReducerSaysWhyADwellOfHugeOutputsHasNoScatter) {
  // Through the library (no reader): a dwell of 1e200 outputs has its revolutions, but their scatter
  // overflows; the refusal says so rather than "too few revolutions".
  const Scenario s = small_test();
  std::vector<RecordSample> rows = record_of(s);
  for (RecordSample& x : rows) x.outputs[0] = 1e200;
  const std::string m = refusal([&] { reduce_rows(s, rows); });
  EXPECT_FALSE(contains(m, "too few")) << m;
  EXPECT_TRUE(contains(m, "1e+200")) << m;
  EXPECT_TRUE(contains(m, "1e+50")) << m;
}

// ---- Configuration values whose products overflow (D13)
// ----------------------------------------------------

TEST(ConfigurationBounds, ValuesBeyondAPhysicalRangeAreRefusedNamingTheKey) {
  struct Case {
    std::string toml, key;
  };
  const std::vector<Case> cases = {
      {"[gyro]\ndF = 1e308\n", "gyro.dF"},
      {"[gyro]\ndIO = -1e300\n", "gyro.dIO"},
      {"[gyro.noise]\nangle_random_walk_deg_rt_h = 1e300\n", "gyro.noise.angle_random_walk_deg_rt_h"},
      {"[gyro.noise]\nrate_random_walk_deg_h_rt_h = 1e300\n", "gyro.noise.rate_random_walk_deg_h_rt_h"},
      {"[centrifuge]\nradius_m = 1e300\n", "centrifuge.radius_m"},
      {"[centrifuge.errors]\nbase_tilt_x_arcsec = 1e300\n", "centrifuge.errors.base_tilt_x_arcsec"},
      {"[centrifuge.errors]\nlever_arm_m = [0.0, 2.0, 0.0]\n", "centrifuge.errors.lever_arm_m[1]"},
      {"[centrifuge.errors]\nmain_runout_x = [ { harmonic = 1, amplitude_m = 5.0, phase_deg = 0.0 } ]\n",
       "centrifuge.errors.main_runout_x[0].amplitude_m"},
      {"[uncertainty]\nradius_error_m = 1e300\n", "uncertainty.radius_error_m"},
      {"[site]\ngravity_m_s2 = 1e300\n", "site.gravity_m_s2"},
      {"[sensor]\nkind = \"accelerometer\"\n[accelerometer]\nK0_ug = 1e308\n", "accelerometer.K0_ug"},
      {"[sensor]\nkind = \"accelerometer\"\n[accelerometer.noise]\nvelocity_random_walk_ug_rt_hz = 1e300\n",
       "accelerometer.noise.velocity_random_walk_ug_rt_hz"},
      {"[record]\nmain_angle_offset_deg = 1e300\n", "record.main_angle_offset_deg"},
  };
  for (const Case& c : cases) {
    const std::string m = test::config_error(c.toml);
    EXPECT_TRUE(contains(m, "rig.toml, line ")) << c.toml << m;
    EXPECT_TRUE(contains(m, c.key + " must be")) << c.toml << m;
  }
  // Generous: a large but physical value is read.
  for (const std::string ok :
       {"[gyro]\ndF = 1e6\n", "[gyro.noise]\nangle_random_walk_deg_rt_h = 100.0\n",
        "[centrifuge]\nradius_m = 20.0\n", "[centrifuge.errors]\nbase_tilt_x_arcsec = 3600.0\n"})
    EXPECT_EQ(test::config_error(ok), "") << ok;
}

TEST(ConfigurationBounds, PlanNamesTheCauseOfAnOutputThatOverflowsItsWeighting) {
  // A scenario built in code (past the configuration's ranges): plan's fit refuses naming the position and
  // the cause, never "Observation 0 is not finite".
  Scenario s = default_scenario();
  s.gyro.values[0] = 1e308;
  const std::string m =
      refusal([&] { predict_calibration(s, calibration_options(s, CalibrationChoices{})); });
  EXPECT_FALSE(m.empty());
  EXPECT_FALSE(contains(m, "Observation 0")) << m;
  EXPECT_TRUE(contains(m, "position 1")) << m;
}

// ---- Outputs in the subnormal range (D13)
// ------------------------------------------------------------------

TEST(TinyOutputs, AVaryingOutputIsNotCalledConstant) {
  // A record's outputs scaled by 1e-300 vary, if tinily: not "the constant ... with no scatter at all", nor a
  // calibration of nonsense (exit 0) once they are no longer called constant.
  const Scenario s = small_test();
  std::vector<RecordSample> rows = record_of(s);
  for (RecordSample& x : rows) x.outputs[0] *= 1e-300;
  const std::string m = refusal([&] {
    const Reduction r = reduce_rows(s, rows);
    CalibrationOptions o;
    identify(r, reduce_model_terms(r, s.model(), ReduceOptions{}), s.model(), o);
  });
  EXPECT_FALSE(contains(m, "the constant")) << m;
  EXPECT_FALSE(contains(m, "no scatter at all")) << m;
  // It is refused naming the cause: a scatter that underflows, and the scale.
  EXPECT_TRUE(contains(m, "underflows")) << m;
  EXPECT_TRUE(contains(m, "output_scale_per_deg_h")) << m;
}

}  // namespace
}  // namespace gyrocal
