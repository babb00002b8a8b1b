// An accelerometer's first day (issue 28, item 8, the smaller findings): what `plan` says about the
// reduction and the test, the reader's refusals naming the key that fixes them, the reducer's unit hints
// naming the right key, `noise` on a record with bias instability, and the data-quality listing. Each case
// failed before its fix.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/sensor/accelerometer.hpp"
#include "support/cli_run.hpp"
#include "support/rig_record.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;
using test::fresh_test_folder;
using test::run_cli;

/// A small accelerometer test on the default machine: a static set and two speeds (6 and 12 rad/s), four
/// beta, the gamma given, 8 revolutions at 50 Hz, 2 s static holds.
Scenario small_accelerometer(const std::vector<double>& gamma_deg) {
  Scenario s = default_scenario();
  s.sensor_kind = SensorKind::kAccelerometer;
  s.accelerometer = Accelerometer{};
  s.test.rates_rad_s = {0.0, 6.0, 12.0};
  s.centrifuge.rate_rad_s = 6.0;
  s.test.revolutions = 8;
  s.test.sample_rate_hz = 50.0;
  s.test.settle_s = 1.0;
  s.test.static_hold_s = 2.0;
  s.test.gamma_rad.clear();
  for (const double g : gamma_deg) s.test.gamma_rad.push_back(g * kDegToRad);
  return s;
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream file(path);
  file << text;
}

/// `gyrocal plan --config DIR/NAME --json - EXTRA` on `s` written to DIR/NAME; the JSON (null if it failed).
nlohmann::json plan_json(const fs::path& dir, const std::string& name, const Scenario& s,
                         const std::string& extra = "") {
  write_text(dir / name, scenario_to_toml(s));
  const test::CliOutcome o = run_cli("plan --config " + (dir / name).string() + " --json - " + extra, dir);
  EXPECT_EQ(o.status, 0) << o.err;
  if (o.status != 0) return nullptr;
  return nlohmann::json::parse(o.out);
}

// ---- a. The gamma list and the reduction plan assumes ----

// The harmonic reduction keeps a spinning dwell's whole harmonic content (seven values at k 360/7 deg)
// whatever [test] gamma_deg lists, so four and eight gamma give the same sigma for every coefficient the
// spinning dwells decide (the quadrature and misalignment terms; K0, K1 and K3 take a share from the static
// holds, which follow gamma_deg); plan says so, and counts the planned and the reduced positions: 3 rates x 4
// beta x G gamma planned, 4 beta x G static holds + 2 speeds x 4 beta x 7 reduced.
TEST(AccelerometerGammaList, HarmonicReductionIgnoresTheSpinningGammaAndPlanSaysSo) {
  const fs::path dir = fresh_test_folder("gyrocal-gamma");
  const nlohmann::json four = plan_json(dir, "four.toml", small_accelerometer({0, 90, 180, 270}));
  const nlohmann::json eight =
      plan_json(dir, "eight.toml", small_accelerometer({0, 45, 90, 135, 180, 225, 270, 315}));
  ASSERT_FALSE(four.is_null());
  ASSERT_FALSE(eight.is_null());
  for (const char* name : {"Kip", "Kio", "Kpo", "delta_p", "delta_o"}) {
    const double a = four["coefficients"][name]["std"].get<double>();
    const double b = eight["coefficients"][name]["std"].get<double>();
    EXPECT_NEAR(a / b, 1.0, 0.02) << name << ": the spinning dwells' values do not depend on gamma_deg";
  }
  for (const nlohmann::json* j : {&four, &eight}) {
    ASSERT_TRUE(j->contains("reduction"));
    EXPECT_EQ((*j)["reduction"]["method"], "harmonic");
    const nlohmann::json& g = (*j)["reduction"]["spinning_gamma_deg"];
    ASSERT_EQ(g.size(), 7u);
    for (std::size_t k = 0; k < 7; ++k)
      EXPECT_NEAR(g[k].get<double>(), 360.0 * static_cast<double>(k) / 7.0, 1e-9);
  }
  EXPECT_EQ(four["reduction"]["positions"], 4 * 4 + 2 * 4 * 7);
  EXPECT_EQ(eight["reduction"]["positions"], 4 * 8 + 2 * 4 * 7);

  const test::CliOutcome text = run_cli("plan --config " + (dir / "four.toml").string(), dir);
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("48 positions (3 rates x 4 beta x 4 gamma)"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("harmonic reduction"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("7 values of its harmonic content"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("gamma_deg sets the static holds only"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("72 reduced positions"), std::string::npos) << text.out;
  fs::remove_all(dir);
}

// With the window reduction (plan --reduction window, as calibrate's) a spinning dwell is read at the four
// gamma 0, 90, 180, 270 deg, where cos^3 = cos: K3 folds onto the scale, plan warns, and the cost shows on
// the cross-axis terms the third harmonic had separated (Kip's sigma grows ~28x on the probe's rig).
TEST(AccelerometerGammaList, PlanTakesReductionWindowWhereFourGammaFoldK3) {
  const fs::path dir = fresh_test_folder("gyrocal-gamma");
  const Scenario s = small_accelerometer({0, 90, 180, 270});
  const nlohmann::json harmonic = plan_json(dir, "four.toml", s);
  const nlohmann::json window = plan_json(dir, "four.toml", s, "--reduction window");
  ASSERT_FALSE(harmonic.is_null());
  ASSERT_FALSE(window.is_null());
  EXPECT_EQ(window["reduction"]["method"], "window");
  EXPECT_EQ(window["reduction"]["positions"], 3 * 4 * 4);
  EXPECT_GT(window["coefficients"]["Kip"]["std"].get<double>(),
            5 * harmonic["coefficients"]["Kip"]["std"].get<double>());
  bool warned = false;
  for (const auto& w : window["warnings"])
    if (w.get<std::string>().find("K3 is confounded with the scale") != std::string::npos) warned = true;
  EXPECT_TRUE(warned) << window["warnings"].dump();
  EXPECT_TRUE(harmonic["warnings"].empty()) << harmonic["warnings"].dump();
  fs::remove_all(dir);
}

// init's comment on gamma_deg says what the list does for an accelerometer: the static holds, and the
// spinning dwells only with reduction = "window".
TEST(AccelerometerGammaList, InitSaysWhatGammaDegSets) {
  const fs::path dir = fresh_test_folder("gyrocal-gamma");
  const test::CliOutcome o = run_cli("init --sensor accelerometer " + (dir / "acc.toml").string(), dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const std::string toml = test::slurp(dir / "acc.toml");
  const std::size_t at = toml.find("gamma_deg = ");
  ASSERT_NE(at, std::string::npos);
  const std::string comment = toml.substr(at, toml.find("rates_rad_s", at) - at);
  EXPECT_NE(comment.find("static holds"), std::string::npos) << comment;
  EXPECT_NE(comment.find("seven values of its harmonic content"), std::string::npos) << comment;
  EXPECT_NE(comment.find("reduction = \"window\""), std::string::npos) << comment;
  fs::remove_all(dir);
}

// ---- c. The reader's refusals name the key that fixes them ----

/// The lab's [record] (the probe's DAQ export): ';', ms, counts, a decimal comma, a units row and a two-line
/// preamble, with the keys given in `keys` (skip_rows, units_row, decimal).
RecordLayout daq_layout(const std::string& keys) {
  const Scenario s = parse_scenario(
      "[sensor]\nkind = \"accelerometer\"\n[record]\ndelimiter = \";\"\ntime_column = \"Zeit_ms\"\n"
      "time_unit = \"ms\"\nmain_angle_column = \"Enc_Arm_cnt\"\ncounter_angle_column = \"Enc_Plat_cnt\"\n"
      "position_angle_column = \"Enc_Pos_cnt\"\nmain_counts_per_revolution = 1048576\n"
      "counter_counts_per_revolution = 1048576\nposition_counts_per_revolution = 262144\n"
      "output_column = \"U_acc_V\"\noutput_scale_per_g = 1.3\n" +
          keys,
      "rig_daq.toml");
  EXPECT_TRUE(s.record.has_value());
  return s.record.value_or(RecordLayout{});
}

const char* const kDaqFile =
    "CF-2 centrifuge DAQ export v3.2\n"
    "Operator: test; Date: 2026-11-27\n"
    "Zeit_ms;U_acc_V;Temp_C;Enc_Pos_cnt;Enc_Arm_cnt;Enc_Plat_cnt\n"
    "ms;V;degC;cnt;cnt;cnt\n"
    "0;0,0000938;21,5;0;0;0\n"
    "5;0,0001012;21,5;0;100;1048476\n"
    "10;0,0000977;21,5;0;200;1048376\n";

/// The refusal reading kDaqFile through `layout` (empty when it reads), and the rows read.
std::string daq_refusal(const RecordLayout& layout, std::size_t* rows = nullptr) {
  try {
    RecordReader reader = RecordReader::from_string(kDaqFile, layout, "daq.csv");
    RecordSample sample;
    std::size_t n = 0;
    while (reader.next(sample)) ++n;
    if (rows) *rows = n;
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(RecordRefusalHints, EachNamesTheKeyThatReadsTheFile) {
  const std::string all = "skip_rows = 2\nunits_row = true\ndecimal = \",\"\n";
  std::size_t rows = 0;
  EXPECT_EQ(daq_refusal(daq_layout(all), &rows), "");
  EXPECT_EQ(rows, 3u);
  // The preamble: its first line is one column at ';'.
  const std::string preamble = daq_refusal(daq_layout("units_row = true\ndecimal = \",\"\n"));
  EXPECT_NE(preamble.find("daq.csv, line 1"), std::string::npos) << preamble;
  EXPECT_NE(preamble.find("record.skip_rows"), std::string::npos) << preamble;
  // The units row under the header.
  const std::string units = daq_refusal(daq_layout("skip_rows = 2\ndecimal = \",\"\n"));
  EXPECT_NE(units.find("line 4"), std::string::npos) << units;
  EXPECT_NE(units.find("'ms'"), std::string::npos) << units;
  EXPECT_NE(units.find("record.units_row = true"), std::string::npos) << units;
  // The decimal comma.
  const std::string comma = daq_refusal(daq_layout("skip_rows = 2\nunits_row = true\n"));
  EXPECT_NE(comma.find("line 5"), std::string::npos) << comma;
  EXPECT_NE(comma.find("'0,0000938'"), std::string::npos) << comma;
  EXPECT_NE(comma.find("record.decimal = \",\""), std::string::npos) << comma;
  // A word in a later row is no units row, and names neither key.
  std::string later = kDaqFile;
  later.replace(later.find("5;0,0001012"), 11, "5;overload");
  try {
    RecordReader reader = RecordReader::from_string(later, daq_layout(all), "daq.csv");
    RecordSample sample;
    while (reader.next(sample)) {
    }
    ADD_FAILURE() << "a word among the rows is read";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'overload', which is not a number"), std::string::npos) << m;
    EXPECT_EQ(m.find("units_row"), std::string::npos) << m;
    EXPECT_EQ(m.find("record.decimal"), std::string::npos) << m;
  }
}

// A preamble line that the delimiter does split (a "key; value" line) names none of the configured columns:
// the refusal names record.skip_rows too.
TEST(RecordRefusalHints, APreambleLineThatSplitsNamesSkipRows) {
  std::string text = kDaqFile;
  text.replace(0, text.find('\n') + 1, "");  // the second preamble line first: "Operator: test; Date: ..."
  const std::string m = [&] {
    try {
      RecordReader reader =
          RecordReader::from_string(text, daq_layout("units_row = true\ndecimal = \",\"\n"), "daq.csv");
      RecordSample sample;
      while (reader.next(sample)) {
      }
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  }();
  EXPECT_NE(m.find("is not a column of the header line"), std::string::npos) << m;
  EXPECT_NE(m.find("record.skip_rows"), std::string::npos) << m;
}

// ---- d. Unit hints that name the right key ----

constexpr std::int64_t kArmCounts = std::int64_t{1} << 20, kPositionCounts = std::int64_t{1} << 18;

std::int64_t wrapped_count(double deg, std::int64_t per_rev) {
  const auto c = static_cast<std::int64_t>(std::llround(deg * static_cast<double>(per_rev) / 360.0));
  return ((c % per_rev) + per_rev) % per_rev;
}

/// The test generator's rig record of small_accelerometer (rates 0, 6, 12 rad/s: they differ by 2) as the
/// lab's DAQ writes it: ms, counts (main and counter 2^20, position 2^18), ';', the output in g. With
/// `counter_reversed` the counter encoder counts the other way.
void write_counts_record(const fs::path& path, bool counter_reversed) {
  const Scenario s = small_accelerometer({0, 90, 180, 270});
  std::ofstream out(path);
  out << "t_ms;arm;plat;pos;acc\n";
  testing::rig_rows(s, testing::RigImperfections{}, testing::RigMotion{}, 7, [&](const testing::RigRow& r) {
    const double counter = counter_reversed ? -r.counter_angle_deg : r.counter_angle_deg;
    out << fmt::format("{};{};{};{};{:.17g}\n", std::llround(r.time_s * 1e3),
                       wrapped_count(r.main_angle_deg, kArmCounts), wrapped_count(counter, kArmCounts),
                       wrapped_count(r.position_angle_deg, kPositionCounts), r.output);
  });
}

/// small_accelerometer's configuration with `rates` and a [record] mapping the counts record: the main
/// and counter columns as given, the counts per revolution as given.
std::string counts_toml(const std::vector<double>& rates, const std::string& main, const std::string& counter,
                        std::int64_t position_counts, std::int64_t main_counts = kArmCounts) {
  Scenario s = small_accelerometer({0, 90, 180, 270});
  s.test.rates_rad_s = rates;
  s.centrifuge.rate_rad_s = rates[1];
  return scenario_to_toml(s) +
         fmt::format(
             "[record]\ndelimiter = \";\"\ntime_column = \"t_ms\"\ntime_unit = \"ms\"\n"
             "main_angle_column = \"{}\"\ncounter_angle_column = \"{}\"\nposition_angle_column = \"pos\"\n"
             "main_counts_per_revolution = {}\ncounter_counts_per_revolution = {}\n"
             "position_counts_per_revolution = {}\noutput_column = \"acc\"\n",
             main, counter, main_counts, kArmCounts, position_counts);
}

TEST(RecordUnitHints, EachMistakeNamesItsOwnKeyNotTheMainEncoder) {
  const fs::path dir = fresh_test_folder("gyrocal-hints");
  write_counts_record(dir / "daq.csv", false);
  write_counts_record(dir / "reversed.csv", true);
  const std::vector<double> rates = {0.0, 6.0, 12.0};
  // The mapping right: the record calibrates (so each refusal below is its mistake's).
  EXPECT_EQ(test::calibrate_in(dir, "daq.csv", counts_toml(rates, "arm", "plat", kPositionCounts)).status, 0);
  struct Mistake {
    std::string what, record, toml;
    std::vector<std::string> said, not_said;
  };
  const std::vector<Mistake> mistakes = {
      {"position counts 2^20 for an encoder of 2^18",
       "daq.csv",
       counts_toml(rates, "arm", "plat", kArmCounts),
       {"record.position_counts_per_revolution = 1048576 the encoder's? It reads 1/4 of the angle",
        "262144 (2^18)"},
       {"main_counts_per_revolution =", "counter_counts_per_revolution =", "2x", "1/2 of"}},
      {"the counter encoder counting the other way",
       "reversed.csv",
       counts_toml(rates, "arm", "plat", kPositionCounts),
       {"does the counter encoder count the other way? Negate the counter angle"},
       {"counts_per_revolution =", "2x", "1/2 of"}},
      {"main and counter columns swapped",
       "daq.csv",
       counts_toml(rates, "plat", "arm", kPositionCounts),
       {"the main axis turns at -6 rad/s and the counter platform at 6 rad/s",
        "are the main and counter columns swapped (record.main_angle_column, record.counter_angle_column)"},
       {"counts_per_revolution =", "2^1"}},
      {"a plan whose rates are off by no clean factor",
       "daq.csv",
       counts_toml({0.0, 5.0, 10.0}, "arm", "plat", kPositionCounts),
       {"no unit explains it: is [test] rates_rad_s the test's?"},
       {"counts_per_revolution =", "2^"}},
      {"main counts 2^19 for 2^20, with rates that differ by 2",
       "daq.csv",
       counts_toml(rates, "arm", "plat", kPositionCounts, kArmCounts / 2),
       {"the main axis turns at 2x the planned rate",
        "is record.main_counts_per_revolution = 524288 the encoder's? It reads 2x the angle"},
       {"position_counts_per_revolution ="}},
  };
  for (const Mistake& m : mistakes) {
    const test::CliOutcome o = test::calibrate_in(dir, m.record, m.toml);
    EXPECT_EQ(o.status, 1) << m.what;
    EXPECT_NE(o.err.find("the record has no usable dwell"), std::string::npos) << m.what << ": " << o.err;
    const std::size_t hint = o.err.find("Check the units: ");
    ASSERT_NE(hint, std::string::npos) << m.what << ": " << o.err;
    const std::string h = o.err.substr(hint);
    for (const std::string& part : m.said) EXPECT_NE(h.find(part), std::string::npos) << m.what << ": " << h;
    for (const std::string& part : m.not_said)
      EXPECT_EQ(h.find(part), std::string::npos) << m.what << ": " << h;
  }
  fs::remove_all(dir);
}

// ---- e. noise: no spurious quantization term beside bias instability ----

/// A static accelerometer's output, g, with the test's own generator: white noise of density n_ug
/// (ug/sqrt(Hz): a sample's std n sqrt(fs)), a bias instability B_ug made as a sum of first-order
/// Gauss-Markov processes with correlation times 1, 10, 100, 1000 s and variances w_i B^2 (the weights that
/// make their Allan deviation ~0.664 B from 2 s on; below 2 s it falls, as any such bias's does), and the
/// output rounded to a 1 ug grid (referred to the input, K1 = 1.3 V/g, written in V with 9 decimals as a DAQ
/// would).
std::vector<double> static_output_g(std::uint64_t seed, double fs, std::size_t n, double n_ug, double b_ug) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  const double times[4] = {1.0, 10.0, 100.0, 1000.0};
  const double weights[4] = {0.909825, 0.698491, 0.750247, 0.696083};
  double state[4];
  for (int i = 0; i < 4; ++i) state[i] = b_ug * std::sqrt(weights[i]) * normal(rng);
  std::vector<double> out(n);
  const double white = n_ug * std::sqrt(fs);
  for (std::size_t k = 0; k < n; ++k) {
    double bias = 0.0;
    for (int i = 0; i < 4; ++i) {
      const double a = std::exp(-1.0 / (fs * times[i]));
      state[i] = a * state[i] + b_ug * std::sqrt(weights[i] * (1.0 - a * a)) * normal(rng);
      bias += state[i];
    }
    const double ug = std::round(1e6 + bias + white * normal(rng));  // 1 g plus the noise, on a 1 ug grid
    // As the DAQ writes it: V at 1.30127 V/g with 9 decimals, read back in g.
    out[k] = std::round(ug * 1e-6 * 1.30127 * 1e9) / 1e9 / 1.30127;
  }
  return out;
}

// Over seeds of 10 ug/sqrt(Hz) white noise and 5 ug bias instability (an hour at 100 Hz each): no velocity
// quantization term is fitted (the record has none: its 1 ug rounding is white), N is within 3 of its
// stated sigma on every seed and unbiased over them, and the 1 ug grid is found although the values went
// through 9 decimals of volts (a rounding of 4e-4 of a step). Before: a spurious term on 4 of 10 seeds, N
// 0.5 % low (-2.5 sigma), and no grid.
TEST(AccelerometerNoiseFit, BiasInstabilityDrawsNoSpuriousQuantizationTerm) {
  const bool sanitized = std::getenv("GYROCAL_SANITIZED") != nullptr;
  const int seeds = sanitized ? 3 : 6;
  const double fs = 100.0, n_true = 10.0;
  const auto n = static_cast<std::size_t>(3600 * fs);
  std::vector<double> time(n);
  for (std::size_t k = 0; k < n; ++k) time[k] = static_cast<double>(k) / fs;
  RecordNoiseOptions options;
  options.sensor = SensorKind::kAccelerometer;
  double z_sum = 0.0;
  for (int seed = 1; seed <= seeds; ++seed) {
    const RecordNoise r = characterise_samples_noise(
        time, static_output_g(static_cast<std::uint64_t>(seed), fs, n, n_true, 5.0), "static.csv", options);
    EXPECT_FALSE(r.noise.term(NoiseTerm::AngleQuantization).present)
        << "seed " << seed << ": velocity quantization " << sensor_term(r, NoiseTerm::AngleQuantization).value
        << " ug s";
    const FittedNoiseTerm nt = sensor_term(r, NoiseTerm::AngleRandomWalk);
    ASSERT_TRUE(nt.present) << seed;
    const double z = (nt.value - n_true) / nt.std;
    EXPECT_LT(std::abs(z), 3.0) << "seed " << seed << ": N " << nt.value << " +- " << nt.std;
    z_sum += z;
    ASSERT_TRUE(r.resolution.has_value()) << "seed " << seed << ": the 1 ug grid is not found";
    EXPECT_NEAR(*r.resolution, 1.0, 1e-3) << seed;
  }
  // The mean z over the seeds: -1.3 (N 0.15 % low), what remains of the bias instability's Allan deviation
  // falling below its floor under 2 s, where the fit's flat term over-predicts it (docs/noise.md); with the
  // spurious term, seeds that drew it gave N 0.5 % low against a sigma twice as large.
  EXPECT_LT(std::abs(z_sum / seeds), 2.0) << z_sum / seeds;
}

// ---- b. plan: every g-level, the test's duration and the record's size ----

// A static set and two speeds: plan names each rate's g-level (omega^2 R0 / g, computed here), and the
// duration, rows and size of the record simulate then writes (the rows counted in the file, its size within
// 2 %).
TEST(PlanStatesTheTest, EveryGLevelTheDurationAndTheRecordSize) {
  const fs::path dir = fresh_test_folder("gyrocal-plan-size");
  const Scenario s = small_accelerometer({0, 90, 180, 270});
  write_text(dir / "acc.toml", scenario_to_toml(s));
  const test::CliOutcome plan = run_cli("plan --config " + (dir / "acc.toml").string(), dir);
  ASSERT_EQ(plan.status, 0) << plan.err;
  for (const double rate : {6.0, 12.0}) {
    const double ar = rate * rate * s.centrifuge.radius_m / s.site.gravity_m_s2;
    const std::string level = fmt::format("{} rad/s: Ar = {:.4g} g", rate, ar);
    EXPECT_NE(plan.out.find(level), std::string::npos) << level << "\n" << plan.out;
  }
  EXPECT_NE(plan.out.find("0 rad/s: static"), std::string::npos) << plan.out;
  const test::CliOutcome sim = run_cli(
      "simulate --config " + (dir / "acc.toml").string() + " --out " + (dir / "acc.csv").string(), dir);
  ASSERT_EQ(sim.status, 0) << sim.err;
  std::size_t rows = 0;
  {
    std::ifstream in(dir / "acc.csv");
    std::string line;
    bool header = false;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      if (!header) {
        header = true;
        continue;
      }
      ++rows;
    }
  }
  const auto bytes = static_cast<double>(fs::file_size(dir / "acc.csv"));
  // "The test lasts D s (H h); simulate writes N rows, about X kB."
  const std::size_t at = plan.out.find("The test lasts ");
  ASSERT_NE(at, std::string::npos) << plan.out;
  double duration = 0, hours = 0, size = 0;
  unsigned long long planned_rows = 0;
  char unit[8] = {};
  ASSERT_EQ(std::sscanf(plan.out.c_str() + at,
                        "The test lasts %lf s (%lf h); simulate writes %llu rows, about %lf %7s", &duration,
                        &hours, &planned_rows, &size, unit),
            5)
      << plan.out.substr(at);
  EXPECT_EQ(planned_rows, rows);
  EXPECT_NEAR(duration, static_cast<double>(rows) / s.test.sample_rate_hz,
              1.0 / s.test.sample_rate_hz + 0.05);
  const double scale = std::string(unit).starts_with("kB")   ? 1e3
                       : std::string(unit).starts_with("MB") ? 1e6
                                                             : 1.0;
  EXPECT_NEAR(size * scale / bytes, 1.0, 0.02) << size << " " << unit << " for " << bytes << " bytes";
  fs::remove_all(dir);
}

// ---- f. A simulated record with K1 != 1: its column's scale stated, noise referred to the input ----

// simulate's accel_g column holds the sensor's output, K1 per g; the record's metadata says so
// (output_scale_per_g = K1) and noise states N in ug referred to the input: 10 ug/sqrt(Hz), not 13.
TEST(AccelerometerRecordScale, NoiseOfARecordWithK1NotOneIsInMicroG) {
  const fs::path dir = fresh_test_folder("gyrocal-k1-noise");
  Scenario s = default_scenario();
  s.sensor_kind = SensorKind::kAccelerometer;
  s.accelerometer = Accelerometer{};
  s.accelerometer.coefficients[AccelCoefficient::K1] = 1.30127;
  s.accelerometer.noise = AccelerometerNoise{};
  s.accelerometer.noise.velocity_random_walk_ug_rt_hz = 10.0;
  s.test.sample_rate_hz = 100.0;
  s.test.rates_rad_s = {0.0};
  s.test.beta_rad = {kPi / 2};
  s.test.gamma_rad = {0.0};
  s.test.settle_s = 0.0;
  s.test.static_hold_s = 600.0;
  write_text(dir / "static.toml", scenario_to_toml(s));
  const test::CliOutcome sim = run_cli(
      "simulate --config " + (dir / "static.toml").string() + " --out " + (dir / "static.csv").string(), dir);
  ASSERT_EQ(sim.status, 0) << sim.err;
  EXPECT_NE(test::slurp(dir / "static.csv").find("\n# output_scale_per_g = 1.30127\n"), std::string::npos);
  const test::CliOutcome noise = run_cli("noise " + (dir / "static.csv").string() + " --json -", dir);
  ASSERT_EQ(noise.status, 0) << noise.err;
  const nlohmann::json j = nlohmann::json::parse(noise.out);
  const double n = j["terms"]["velocity_random_walk_ug_rt_hz"]["value"].get<double>();
  const double sigma = j["terms"]["velocity_random_walk_ug_rt_hz"]["std"].get<double>();
  EXPECT_LT(std::abs(n - 10.0), 4.0 * sigma) << n << " +- " << sigma;
  fs::remove_all(dir);
}

// ---- g. The data-quality listing without clutter ----

// A static set's indexing moves (the main axis stopped, the counter platform turning between holds) are
// counted in one line; a static hold that ends because the machine starts to move says so in rad/s, not as a
// change relative to a stopped rate; a short static hold is measured against [test] static_hold_s, not
// revolutions. The record's holds last 2 s, the configuration plans 4 s.
TEST(DataQualityListing, IndexingMovesInOneLineStoppedRatesInRadPerSecondHoldsInSeconds) {
  const fs::path dir = fresh_test_folder("gyrocal-quality");
  const Scenario s = small_accelerometer({0, 90, 180, 270});
  write_text(dir / "acc.toml", scenario_to_toml(s));
  ASSERT_EQ(
      run_cli("simulate --config " + (dir / "acc.toml").string() + " --out " + (dir / "acc.csv").string(),
              dir)
          .status,
      0);
  Scenario longer = s;
  longer.test.static_hold_s = 4.0;
  write_text(dir / "longer.toml", scenario_to_toml(longer));
  const test::CliOutcome o =
      run_cli("calibrate " + (dir / "acc.csv").string() + " --config " + (dir / "longer.toml").string(), dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const std::string text = o.out + o.err;
  std::size_t listed = 0, counted = 0;
  for (std::size_t at = 0; (at = text.find("\n- ", at)) != std::string::npos; ++at) {
    const std::string line = text.substr(at + 1, text.find('\n', at + 1) - at - 1);
    if (line.find("no dwell from the steady run") != std::string::npos &&
        line.find("stands still while the counter platform turns") != std::string::npos)
      ++listed;
    if (line.find("indexing moves") != std::string::npos) ++counted;
  }
  EXPECT_EQ(listed, 0u) << text;
  EXPECT_EQ(counted, 1u) << text;
  EXPECT_EQ(text.find("(relative; rate_steadiness"), std::string::npos) << text;
  EXPECT_NE(text.find("the stopped machine starts to move"), std::string::npos) << text;
  EXPECT_NE(text.find("s planned ([test] static_hold_s)"), std::string::npos) << text;
  EXPECT_EQ(text.find("s planned (8 revolutions)"), std::string::npos) << text;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gyrocal
