// A unit's history summarised (history/summary.hpp) and written as `history show --json` states it
// (result/history_json.hpp; docs/interface.md "Calibration history (SQLite)"): the runs grouped per channel's
// coefficient and per machine error, in the runs' order, the runs that did not identify a quantity listed
// apart, the statistics of each, the flags per run; and end to end, 20 simulated calibrations of one
// accelerometer whose bias K0 is redrawn per run (a turn-on scatter), whose repeatability the summary finds.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/random.hpp"
#include "gyrocal/history/summary.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/result/history_json.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace gyrocal {
namespace {

using history::CoefficientValue;
using history::HistorySummary;
using history::MachineErrorValue;
using history::QuantityHistory;

bool sanitized() {
  return std::getenv("GYROCAL_SANITIZED") != nullptr;
}

history::Run make_run(std::int64_t id, const std::string& date, std::vector<CoefficientValue> coefficients,
                      std::vector<MachineErrorValue> machine_errors = {}, std::string sensor = "gyro") {
  history::Run r;
  r.id = id;
  r.unit = "SN1";
  r.date = date;
  r.date_source = "option";
  r.sensor = sensor;
  r.channels = {sensor};
  r.record_sha256 = std::string(63, '0') + std::to_string(id % 10);
  r.gyrocal_version = "1.0";
  r.note = fmt::format("run {}", id);
  r.coefficients = std::move(coefficients);
  r.machine_errors = std::move(machine_errors);
  return r;
}

CoefficientValue coefficient(const std::string& name, std::optional<double> value, std::optional<double> std,
                             const std::string& channel = "gyro", const std::string& unit = "deg/h") {
  return {channel, name, value, std, unit, value.has_value()};
}

const QuantityHistory& find(const std::vector<QuantityHistory>& list, const std::string& channel,
                            const std::string& name) {
  for (const QuantityHistory& q : list)
    if (q.channel == channel && q.name == name) return q;
  throw std::runtime_error("no quantity " + channel + "/" + name);
}

TEST(HistorySummary, GroupsTheRunsPerQuantityInDateOrder) {
  // Given out of date order: run 3 (Jan 1), run 1 (Jan 3), run 2 (Jan 2, 12:00). Date order: 3, 2, 1.
  std::vector<history::Run> runs;
  runs.push_back(make_run(
      3, "2026-01-01", {coefficient("dF", 1.0, 0.5), coefficient("dI", 2.0, 1.0), coefficient("dO", {}, {})},
      {{"radius_error", 1e-5, 1e-6, "m"}}));
  runs.push_back(make_run(1, "2026-01-03",
                          {coefficient("dF", 2.0, 0.5), coefficient("dI", 4.0, 0.0),
                           coefficient("dO", {}, {}), coefficient("dS", 1.0, 0.1)}));
  runs.push_back(
      make_run(2, "2026-01-02T12:00:00Z",
               {coefficient("dF", 3.0, 0.5), coefficient("dI", 3.0, 1.0), coefficient("dO", {}, {})},
               {{"radius_error", 3e-5, 1e-6, "m"}, {"counter_wobble_x:2:cos", 0.5, 0.1, "arcsec"}}));
  const HistorySummary s = history::summarize("SN1", runs);
  EXPECT_EQ(s.unit, "SN1");
  EXPECT_EQ(s.sensor, "gyro");
  ASSERT_EQ(s.runs.size(), 3u);
  EXPECT_EQ(s.runs[0].id, 3);
  EXPECT_EQ(s.runs[1].id, 2);
  EXPECT_EQ(s.runs[2].id, 1);
  // Coefficients in the runs' order of first appearance (dS first appears in run 1, the last by date).
  ASSERT_EQ(s.coefficients.size(), 4u);
  EXPECT_EQ(s.coefficients[0].name, "dF");
  EXPECT_EQ(s.coefficients[1].name, "dI");
  EXPECT_EQ(s.coefficients[2].name, "dO");
  EXPECT_EQ(s.coefficients[3].name, "dS");
  const QuantityHistory& df = s.coefficients[0];
  EXPECT_EQ(df.channel, "gyro");
  EXPECT_EQ(df.unit, "deg/h");
  ASSERT_EQ(df.values.size(), 3u);
  // Days since 1970-01-01: 2026-01-01 is day 20454 (56 years of 365 days + 14 leap days, 1972..2024).
  EXPECT_EQ(df.values[0].day, 20454.0);
  EXPECT_EQ(df.values[1].day, 20455.5);
  EXPECT_EQ(df.values[2].day, 20456.0);
  EXPECT_EQ(df.values[1].value, 3.0);
  EXPECT_EQ(df.values[1].run_id, 2);
  ASSERT_TRUE(df.stats);
  EXPECT_EQ(df.stats->runs, 3u);
  EXPECT_NEAR(df.stats->mean, 2.0, 1e-12);  // equal weights: (1 + 3 + 2) / 3
  // dI: run 1's std of 0 states nothing: unidentified, the other two stated.
  const QuantityHistory& di = s.coefficients[1];
  ASSERT_EQ(di.values.size(), 2u);
  EXPECT_EQ(di.unidentified, std::vector<std::int64_t>{1});
  // dO: no run identified it: all three unidentified (date order), no statistics.
  const QuantityHistory& d_o = s.coefficients[2];
  EXPECT_TRUE(d_o.values.empty());
  EXPECT_EQ(d_o.unidentified, (std::vector<std::int64_t>{3, 2, 1}));
  EXPECT_FALSE(d_o.stats);
  // dS: one run; runs that do not hold it are neither stated nor unidentified.
  const QuantityHistory& ds = s.coefficients[3];
  ASSERT_EQ(ds.values.size(), 1u);
  EXPECT_TRUE(ds.unidentified.empty());
  EXPECT_FALSE(ds.stats->run_to_run_std);
  // The machine errors: the rig's, channel "", by first appearance.
  ASSERT_EQ(s.machine_errors.size(), 2u);
  EXPECT_EQ(s.machine_errors[0].name, "radius_error");
  EXPECT_EQ(s.machine_errors[0].channel, "");
  EXPECT_EQ(s.machine_errors[0].unit, "m");
  EXPECT_EQ(s.machine_errors[0].values.size(), 2u);
  EXPECT_NEAR(s.machine_errors[0].stats->mean, 2e-5, 1e-18);
  EXPECT_EQ(s.machine_errors[1].name, "counter_wobble_x:2:cos");
}

TEST(HistorySummary, AnImusChannelsComeInTheRunsOrder) {
  history::Run a = make_run(1, "2026-02-01", {}, {}, "imu");
  a.channels = {"gyro_x", "accel_x"};
  a.coefficients = {coefficient("K0", 10.0, 1.0, "accel_x", "ug"), coefficient("dF", 0.1, 0.01, "gyro_x"),
                    coefficient("K1", 1.0, 1e-4, "accel_x", "output/g")};
  history::Run b = a;
  b.id = 2;
  b.date = "2026-02-02";
  const HistorySummary s = history::summarize("IMU7", {a, b});
  ASSERT_EQ(s.coefficients.size(), 3u);
  EXPECT_EQ(s.coefficients[0].channel, "gyro_x");
  EXPECT_EQ(s.coefficients[1].channel, "accel_x");
  EXPECT_EQ(s.coefficients[1].name, "K0");
  EXPECT_EQ(s.coefficients[2].name, "K1");
  EXPECT_EQ(s.coefficients[2].unit, "output/g");
}

TEST(HistorySummary, RefusesNoRunsAndADamagedDate) {
  try {
    history::summarize("SN404", {});
    ADD_FAILURE() << "no runs accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'SN404' has no runs"), std::string::npos) << e.what();
  }
  for (const char* date :
       {"2026-1-01", "yesterday", "2026-13-01", "2026-01-01T25:00:00", "2026-01-01 10:00:00"}) {
    try {
      history::summarize("SN1", {make_run(5, date, {coefficient("dF", 1.0, 0.1)})});
      ADD_FAILURE() << "accepted " << date;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(fmt::format("run 5 of unit 'SN1': '{}' is not a date", date)),
                std::string::npos)
          << e.what();
    }
  }
}

/// Twenty runs of one gyro, a day apart, whose dF scatters by 0.01 about 1 and whose run 10 is 1 higher; the
/// rig's radius error in every run.
std::vector<history::Run> twenty_runs_with_an_outlier() {
  std::vector<history::Run> runs;
  for (int i = 1; i <= 20; ++i) {
    const double df = 1.0 + 0.01 * ((i * 7) % 5 - 2) + (i == 10 ? 1.0 : 0.0);
    runs.push_back(make_run(i, fmt::format("2026-03-{:02d}", i),
                            {coefficient("dF", df, 0.01), coefficient("dO", {}, {})},
                            {{"radius_error", 1e-5 * (1 + 0.01 * (i % 3)), 1e-7, "m"}}));
  }
  return runs;
}

TEST(HistoryJson, StatesTheContractsShape) {
  const nlohmann::ordered_json j = history_to_json(history::summarize("SN1", twenty_runs_with_an_outlier()));
  std::vector<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.push_back(k);
  EXPECT_EQ(keys, (std::vector<std::string>{"unit", "sensor", "runs", "channels", "machine_errors"}));
  EXPECT_EQ(j["unit"], "SN1");
  EXPECT_EQ(j["sensor"], "gyro");
  ASSERT_EQ(j["runs"].size(), 20u);
  const auto& run0 = j["runs"][0];
  keys.clear();
  for (const auto& [k, v] : run0.items()) keys.push_back(k);
  EXPECT_EQ(keys, (std::vector<std::string>{"id", "date", "record_sha256", "note", "date_source",
                                            "gyrocal_version", "flags"}));
  EXPECT_EQ(run0["id"], 1);
  EXPECT_EQ(run0["date"], "2026-03-01");
  EXPECT_EQ(run0["note"], "run 1");
  EXPECT_EQ(run0["date_source"], "option");

  const auto& df = j["channels"]["gyro"]["dF"];
  keys.clear();
  for (const auto& [k, v] : df.items()) keys.push_back(k);
  EXPECT_EQ(keys,
            (std::vector<std::string>{"unit", "runs", "unidentified", "mean", "mean_std", "run_to_run_std",
                                      "run_to_run_std_low", "run_to_run_std_high", "mean_stated_std",
                                      "std_ratio", "f_test_p", "trend_per_day", "trend_std", "trend_p",
                                      "limits", "flagged", "ewma", "ewma_limits", "ewma_flagged"}));
  EXPECT_EQ(df["unit"], "deg/h");
  ASSERT_EQ(df["runs"].size(), 20u);
  EXPECT_EQ(df["runs"][9]["id"], 10);
  EXPECT_EQ(df["runs"][9]["date"], "2026-03-10");
  EXPECT_NEAR(df["runs"][9]["value"].get<double>(), 2.0 + 0.01 * ((70 % 5) - 2), 1e-12);
  EXPECT_EQ(df["runs"][9]["std"], 0.01);
  EXPECT_TRUE(df["unidentified"].empty());
  EXPECT_TRUE(df["mean"].is_number() && df["trend_p"].is_number() && df["f_test_p"].is_number());
  ASSERT_EQ(df["limits"].size(), 2u);
  EXPECT_LT(df["limits"][0].get<double>(), df["limits"][1].get<double>());
  // The outlier 1 (100 sigma) above the others is the individuals chart's only flag.
  EXPECT_EQ(df["flagged"], nlohmann::ordered_json::array({10}));
  EXPECT_EQ(df["ewma"].size(), 20u);
  EXPECT_EQ(df["ewma_limits"].size(), 20u);
  EXPECT_EQ(df["ewma_limits"][0].size(), 2u);

  // dO: no run identified it: every statistic null, every list empty, its runs all unidentified.
  const auto& d_o = j["channels"]["gyro"]["dO"];
  EXPECT_TRUE(d_o["runs"].empty());
  EXPECT_EQ(d_o["unidentified"].size(), 20u);
  for (const char* key :
       {"mean", "mean_std", "run_to_run_std", "run_to_run_std_low", "run_to_run_std_high", "mean_stated_std",
        "std_ratio", "f_test_p", "trend_per_day", "trend_std", "trend_p", "limits"})
    EXPECT_TRUE(d_o[key].is_null()) << key;
  for (const char* key : {"flagged", "ewma", "ewma_limits", "ewma_flagged"})
    EXPECT_TRUE(d_o[key].is_array() && d_o[key].empty()) << key;

  // The machine errors, and each run's flags: the quantities whose individuals chart or EWMA flagged it.
  ASSERT_TRUE(j["machine_errors"].contains("radius_error"));
  const auto& radius = j["machine_errors"]["radius_error"];
  EXPECT_EQ(radius["unit"], "m");
  for (const auto& run : j["runs"]) {
    std::set<std::string> expected;
    for (const auto& [label, entry] : {std::pair<std::string, const nlohmann::ordered_json*>{"gyro/dF", &df},
                                       {"machine/radius_error", &radius}}) {
      for (const char* list : {"flagged", "ewma_flagged"})
        for (const auto& id : (*entry)[list])
          if (id == run["id"]) expected.insert(label);
    }
    const std::set<std::string> flags(run["flags"].begin(), run["flags"].end());
    EXPECT_EQ(flags, expected) << run["id"];
    EXPECT_EQ(flags.size(), run["flags"].size()) << "a label twice";
  }
  EXPECT_EQ(j["runs"][9]["flags"][0], "gyro/dF");
}

TEST(HistoryJson, OneRunHasItsMeanAndNullsForTheRest) {
  const nlohmann::ordered_json j =
      history_to_json(history::summarize("SN1", {make_run(1, "2026-01-01", {coefficient("dF", 0.5, 0.1)})}));
  const auto& df = j["channels"]["gyro"]["dF"];
  EXPECT_EQ(df["mean"], 0.5);
  EXPECT_EQ(df["mean_std"], 0.1);
  EXPECT_EQ(df["mean_stated_std"], 0.1);
  for (const char* key : {"run_to_run_std", "run_to_run_std_low", "run_to_run_std_high", "std_ratio",
                          "f_test_p", "trend_per_day", "trend_std", "trend_p", "limits"})
    EXPECT_TRUE(df[key].is_null()) << key;
  EXPECT_TRUE(j["machine_errors"].is_object() && j["machine_errors"].empty());
  EXPECT_TRUE(j["runs"][0]["flags"].empty());
}

TEST(HistoryJson, ANumberThatIsNotFiniteIsWrittenAsNull) {
  // Values of 1e300 and -1e300: their mean is finite, but the sample variance overflows to infinity.
  std::vector<history::Run> runs = {make_run(1, "2026-01-01", {coefficient("dF", 1e300, 1.0)}),
                                    make_run(2, "2026-01-02", {coefficient("dF", -1e300, 1.0)})};
  const nlohmann::ordered_json j = history_to_json(history::summarize("SN1", runs));
  const auto& df = j["channels"]["gyro"]["dF"];
  EXPECT_TRUE(df["run_to_run_std"].is_null());
  EXPECT_TRUE(df["mean_std"].is_null());
  EXPECT_EQ(df["mean"], 0.0);
  EXPECT_EQ(df["f_test_p"], 0.0);  // a chi2 beyond any doubt
  // And the JSON text holds no "inf" or "nan".
  const std::string text = j.dump();
  EXPECT_EQ(text.find("inf"), std::string::npos);
  EXPECT_EQ(text.find("nan"), std::string::npos);
}

// ---- End to end: the library's simulator and calibration, 20 runs of one accelerometer ----

/// A small accelerometer test (as tests/test_accelerometer_calibrate.cpp's): static holds, 6 and 12 rad/s,
/// 8 revolutions at 50 Hz, so that a run is simulated, reduced and identified in milliseconds.
Scenario accelerometer_scenario() {
  Scenario s = default_scenario();
  s.sensor_kind = SensorKind::kAccelerometer;
  s.accelerometer = Accelerometer{};
  s.test.rates_rad_s = {0.0, 6.0, 12.0};
  s.centrifuge.rate_rad_s = 6.0;
  s.test.revolutions = 8;
  s.test.sample_rate_hz = 50.0;
  s.test.settle_s = 2.0;
  s.test.static_hold_s = 2.0;
  return s;
}

/// The calibration of one simulated record of `truth`, as `gyrocal calibrate` computes it.
CalibrationResult calibrate_accelerometer(const Scenario& config, const Scenario& truth, std::uint64_t seed) {
  const ReduceOptions ro;
  const TestSpec plan = reduction_plan(truth.test, SensorKind::kAccelerometer, ro);
  Reducer reducer(plan, ro, "simulated", truth.centrifuge.rate_rad_s);
  SimulationOptions so;
  so.seed = seed;
  simulate(truth, so, [&](const RecordSample& sample) { reducer.push(sample); });
  const Reduction reduction = reducer.finish();
  CalibrationOptions o;
  o.sensor = SensorKind::kAccelerometer;
  const CentrifugeModel model = config.model();
  return identify(reduction, reduce_sensor_model_terms(reduction, model, o.reduce, config.channels().front()),
                  model, o);
}

/// The run a history keeps of a calibration result: its coefficients, filled by hand.
history::Run run_of(const CalibrationResult& r, std::int64_t id, const std::string& date) {
  history::Run run = make_run(id, date, {}, {}, "accelerometer");
  for (const CoefficientEstimate& c : r.coefficients) {
    CoefficientValue v{"accelerometer", c.name, std::nullopt, std::nullopt, c.unit, c.identifiable};
    if (c.identifiable) v.value = c.value, v.std = c.std;
    run.coefficients.push_back(v);
  }
  return run;
}

/// 20 runs of one accelerometer whose K0 (ug) is the default plus tau_ug * N(0, 1), redrawn per run.
std::vector<history::Run> accelerometer_history(double tau_ug, std::uint64_t seed, int runs = 20) {
  const Scenario config = accelerometer_scenario();
  RandomSource turn_on(seed, 7);
  std::vector<history::Run> out;
  for (int i = 0; i < runs; ++i) {
    Scenario truth = config;
    truth.accelerometer.coefficients.values[0] += tau_ug * turn_on.normal();  // K0
    const CalibrationResult r =
        calibrate_accelerometer(config, truth, seed * 1000 + static_cast<std::uint64_t>(i));
    out.push_back(run_of(r, i + 1, fmt::format("2026-04-{:02d}", i + 1)));
  }
  return out;
}

TEST(HistoryEndToEnd, TwentyCalibrationsWithATurnOnScatterOfK0) {
  // Without a turn-on scatter the stated sigma explain the runs' scatter; their mean is K0's stated sigma.
  const HistorySummary quiet = history::summarize("ACC1", accelerometer_history(0.0, 1));
  const QuantityHistory& k0_quiet = find(quiet.coefficients, "accelerometer", "K0");
  ASSERT_TRUE(k0_quiet.stats);
  ASSERT_EQ(k0_quiet.stats->runs, 20u);
  EXPECT_GT(*k0_quiet.stats->f_test_p, 1e-3);
  EXPECT_NEAR(*k0_quiet.stats->std_ratio, 1.0, 0.5);
  EXPECT_NEAR(k0_quiet.stats->mean, 50.0, 4.0 * k0_quiet.stats->mean_std);
  const double sigma = k0_quiet.stats->mean_stated_std;
  std::printf("without turn-on scatter: K0 run-to-run std %.3g ug, stated %.3g ug, F-test p %.2g\n",
              *k0_quiet.stats->run_to_run_std, sigma, *k0_quiet.stats->f_test_p);
  // K0's turn-on scatter tau = 3 sigma: the run-to-run std's truth is sqrt(tau^2 + sigma^2) = sqrt(10) sigma.
  const double tau = 3.0 * sigma;
  const double truth = std::hypot(tau, sigma);
  const int histories = sanitized() ? 2 : 6;
  int covered = 0;
  for (int h = 0; h < histories; ++h) {
    const HistorySummary s = history::summarize("ACC1", accelerometer_history(tau, 100 + h));
    const Repeatability& k0 = *find(s.coefficients, "accelerometer", "K0").stats;
    // The F-test flags the scatter the stated sigma do not explain.
    EXPECT_LT(*k0.f_test_p, 1e-3) << h;
    if (*k0.run_to_run_std_low <= truth && truth <= *k0.run_to_run_std_high) ++covered;
    std::printf("history %d: K0 run-to-run std %.3g [%.3g, %.3g] ug, F-test p %.2g\n", h, *k0.run_to_run_std,
                *k0.run_to_run_std_low, *k0.run_to_run_std_high, *k0.f_test_p);
    // Within 3 of its own sigma: 19 s^2 / truth^2 between chi2(19)'s 0.00135 and 0.99865 quantiles, by
    // Wilson and Hilferty's cube-root approximation (1931), k (1 - 2/(9k) -/+ 3 sqrt(2/(9k)))^3: 5.56, 42.98.
    const double c = 2.0 / (9.0 * 19.0);
    const double q_low = 19.0 * std::pow(1.0 - c - 3.0 * std::sqrt(c), 3.0);
    const double q_high = 19.0 * std::pow(1.0 - c + 3.0 * std::sqrt(c), 3.0);
    EXPECT_GT(*k0.run_to_run_std, truth * std::sqrt(q_low / 19.0)) << h;
    EXPECT_LT(*k0.run_to_run_std, truth * std::sqrt(q_high / 19.0)) << h;
    // The other coefficients carry no turn-on scatter.
    EXPECT_GT(*find(s.coefficients, "accelerometer", "K1").stats->f_test_p, 1e-4) << h;
  }
  std::printf("K0: stated sigma %.3g ug; %d of %d 68 %% intervals hold the truth %.3g ug\n", sigma, covered,
              histories, truth);
  // 68 % intervals: P(at most 1 of 6 covers) = 0.011 (binomial), so at least 2 (under the sanitizers,
  // 2 histories: at least 1 of 2, failing with probability 0.1).
  EXPECT_GE(covered, sanitized() ? 1 : 2);
}

}  // namespace
}  // namespace gyrocal
