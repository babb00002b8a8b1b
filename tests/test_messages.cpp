// What the command line says (issue 11, items 5, 6, 9, 11 and 12): refusals that name the key at fault, one
// feasibility check shared by plan, simulate and calibrate, a record's metadata against its configuration,
// numbers printed with the digits their uncertainty justifies, the plan's cost independent of the test's
// length.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include "support/cli_run.hpp"

#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/model_terms.hpp"
#include "gyrocal/reduce/dwell_accumulator.hpp"
#include "gyrocal/reduce/feasibility.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;

using Outcome = test::CliOutcome;
using test::slurp;

class Messages : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::fresh_test_folder("gyrocal-messages"); }
  void TearDown() override { fs::remove_all(dir_); }

  Outcome run(const std::string& args) const { return test::run_cli(args, dir_); }
  fs::path path(const std::string& name) const { return dir_ / name; }
  /// The default scenario's configuration with `key = value` of [test] (or another section) replaced.
  std::string config(const std::string& name,
                     const std::vector<std::pair<std::string, std::string>>& set) const {
    std::string text = scenario_to_toml(default_scenario());
    for (const auto& [key, value] : set) {
      const std::regex line("(^|\n)" + key + " = [^\n]*");
      EXPECT_TRUE(std::regex_search(text, line)) << key;
      // The first line of the key: the section it is read from ([site] gravity_m_s2, not [uncertainty]'s).
      text =
          std::regex_replace(text, line, "$1" + key + " = " + value, std::regex_constants::format_first_only);
    }
    std::ofstream(path(name)) << text;
    return path(name).string();
  }

  fs::path dir_;
};

// ---- Item 12: the program's own usage
// ----------------------------------------------------------------------

TEST_F(Messages, AloneItListsTheSubcommandsAndFailsAsAUsageError) {
  const Outcome o = run("");
  EXPECT_EQ(o.status, 106);  // CLI11's RequiredError, like any missing argument (docs/interface.md)
  for (const char* sub :
       {"demo", "init", "inputs", "simulate", "calibrate", "plan", "sensitivity", "montecarlo", "report"})
    EXPECT_NE(o.err.find(std::string("  ") + sub + " "), std::string::npos) << sub << "\n" << o.err;
}

TEST_F(Messages, VersionPrintsTheProjectVersion) {
  const Outcome o = run("--version");
  EXPECT_EQ(o.status, 0) << o.err;
  EXPECT_TRUE(std::regex_search(o.out, std::regex("^gyrocal [0-9]+\\.[0-9]+\\.[0-9]+\n$"))) << o.out;
}

TEST_F(Messages, EveryChoiceValuedOptionListsItsChoicesInHelpAndError) {
  const std::string methods = "{closed-form,least-squares}";
  for (const char* sub : {"calibrate", "plan", "montecarlo"}) {
    // The Monte Carlo also has compensation "self" (docs/montecarlo.md).
    const std::string compensations =
        std::string(sub) == "montecarlo" ? "{none,seed,full,self}" : "{none,seed,full}";
    const Outcome help = run(std::string(sub) + " --help");
    EXPECT_NE(help.out.find(methods), std::string::npos) << sub;
    EXPECT_NE(help.out.find(compensations), std::string::npos) << sub;
    const Outcome bad_method = run(std::string(sub) + " RECORD --trials 2 --method fast");
    EXPECT_NE(bad_method.status, 0) << sub;
    EXPECT_NE(bad_method.err.find(methods), std::string::npos) << sub << ": " << bad_method.err;
    const Outcome bad_comp = run(std::string(sub) + " RECORD --trials 2 --compensation most");
    EXPECT_NE(bad_comp.status, 0) << sub;
    EXPECT_NE(bad_comp.err.find(compensations), std::string::npos) << sub << ": " << bad_comp.err;
  }
  EXPECT_NE(run("calibrate --help").out.find("{harmonic,window}"), std::string::npos);
}

// ---- Item 11: non-finite numbers in options
// ----------------------------------------------------------------

TEST_F(Messages, NonFiniteNumbersAreRefusedInEveryNumericOption) {
  for (const std::string args : {"inputs --beta-deg nan --time-s 1", "inputs --beta-deg 0 --time-s inf",
                                 "inputs --beta-deg 0 --gamma-deg -inf",
                                 "inputs --beta-deg NaN --gamma-deg 0", "sensitivity --threshold nan"}) {
    const Outcome o = run(args);
    EXPECT_NE(o.status, 0) << args;
    EXPECT_NE(o.err.find("finite"), std::string::npos) << args << ": " << o.err;
    EXPECT_TRUE(o.out.empty()) << args;
  }
}

// ---- Item 12: numbers with the digits their uncertainty justifies -----------------------------------------

/// The "value ± std" of a table line that starts with `name`.
std::pair<double, double> table_value(const std::string& table, const std::string& name) {
  std::smatch m;
  const std::regex line("\n" + name + " +([-+0-9.e]+) ± ([0-9.e+-]+) ");
  if (!std::regex_search(table, m, line)) return {NAN, NAN};
  return {std::stod(m[1]), std::stod(m[2])};
}

TEST_F(Messages, TablesPrintTheStdToTwoSignificantDigitsWhateverItsSize) {
  // Angle random walks from 1e-9 to 1e4 deg/sqrt(h): stds from ~1e-12 to ~1e4 times the default's. The
  // table's std must read as the JSON's to two significant digits (never "± 0.000000"), its value as the
  // truth to the std's last digit.
  for (const char* arw : {"1e-9", "0.002", "1e4"}) {
    const std::string cfg = config(std::string("arw") + arw + ".toml", {{"angle_random_walk_deg_rt_h", arw}});
    const Outcome table = run("plan --config " + cfg);
    ASSERT_EQ(table.status, 0) << table.err;
    EXPECT_FALSE(std::regex_search(table.out, std::regex("± 0\\.0+ "))) << table.out;
    const Outcome json = run("plan --json - --config " + cfg);
    ASSERT_EQ(json.status, 0) << json.err;
    const nlohmann::json j = nlohmann::json::parse(json.out);
    for (const char* name : {"dI", "dO", "dS", "dIO", "dIS", "dOS"}) {
      const double std = j["coefficients"][name]["std"], value = j["coefficients"][name]["value"];
      const auto [v, s] = table_value(table.out, name);
      EXPECT_NEAR(s, std, 0.051 * std) << arw << " " << name << "\n" << table.out;
      EXPECT_NEAR(v, value, 0.051 * std + 1e-12 * std::abs(value)) << arw << " " << name;
    }
  }
}

// ---- Item 12: plan's own prediction
// ------------------------------------------------------------------------

TEST_F(Messages, PlanRaisesNoChi2WarningOnItsOwnNoiseFreePrediction) {
  const Outcome o = run("plan --json -");
  ASSERT_EQ(o.status, 0) << o.err;
  const nlohmann::json j = nlohmann::json::parse(o.out);
  ASSERT_FALSE(j["warnings"].empty());  // the unidentifiable direction's is there
  for (const auto& w : j["warnings"]) EXPECT_EQ(w.get<std::string>().find("chi2"), std::string::npos) << w;
}

// ---- Item 6: one feasibility check for plan, simulate and calibrate ---------------------------------------

TEST_F(Messages, PlanSimulateAndCalibrateRefuseTooFewSamplesPerRevolutionAlike) {
  // 10 Hz at 9.9 rad/s: 6.35 samples per revolution; the harmonic fit of order 3 needs 14, i.e. 22.06 Hz.
  const Outcome good = run("simulate --out " + path("r.csv").string() + " --config " +
                           config("short.toml", {{"revolutions", "3"}}));
  ASSERT_EQ(good.status, 0) << good.err;
  const std::string cfg = config("slow.toml", {{"sample_rate_hz", "10.0"}});
  const Outcome plan = run("plan --config " + cfg);
  const Outcome simulate = run("simulate --out " + path("new.csv").string() + " --config " + cfg);
  const Outcome calibrate = run("calibrate " + path("r.csv").string() + " --config " + cfg);
  for (const Outcome* o : {&plan, &simulate, &calibrate}) {
    EXPECT_EQ(o->status, 1) << o->err;
    EXPECT_NE(o->err.find("sample_rate_hz"), std::string::npos) << o->err;
    EXPECT_NE(o->err.find("6.35 samples per revolution"), std::string::npos) << o->err;
    EXPECT_NE(o->err.find("at least 14"), std::string::npos) << o->err;
    EXPECT_NE(o->err.find("22.06 Hz"), std::string::npos) << o->err;
    EXPECT_EQ(o->err, plan.err);  // one check, one sentence
  }
  EXPECT_FALSE(fs::exists(path("new.csv")));
}

TEST(Feasibility, NeedsTwiceTheFitsUnknownsPerRevolutionAndAFastEnoughRate) {
  TestSpec t;
  ReduceOptions o;
  EXPECT_EQ(min_samples_per_revolution(o), 14);
  t.rates_rad_s = {2.0 * kPi};  // one revolution per second
  t.sample_rate_hz = 14.0;
  EXPECT_NO_THROW(check_test_feasible(t, o, 9.9));
  t.sample_rate_hz = 13.9;
  EXPECT_THROW(check_test_feasible(t, o, 9.9), Error);
  o.harmonic_order = 2;  // 10 samples per revolution suffice
  EXPECT_NO_THROW(check_test_feasible(t, o, 9.9));
  // A non-zero rate slower than the reducer's "stopped" threshold would read as a static set.
  t.sample_rate_hz = 200.0;
  t.revolutions = 1;
  t.rates_rad_s = {1e-6};
  try {
    check_test_feasible(t, ReduceOptions{}, 9.9);
    ADD_FAILURE() << "1e-6 rad/s accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("rates_rad_s"), std::string::npos) << e.what();
  }
}

TEST(Feasibility, RefusesATestOfMoreSamplesThanCanBeSimulatedOrCalibrated) {
  TestSpec t;  // 4 dwells of 200 revolutions at 9.9 rad/s, 2 s settle each, 200 Hz
  const double per_dwell_s = 200 * 2.0 * kPi / 9.9 + 2.0;
  EXPECT_NEAR(planned_test_samples(t, 9.9), 4 * per_dwell_s * 200.0, 1e-6);
  EXPECT_NO_THROW(check_test_feasible(t, ReduceOptions{}, 9.9));
  t.revolutions = 2147483647;  // the 27-hour plan of issue 11: 1.1e12 samples
  try {
    check_test_feasible(t, ReduceOptions{}, 9.9);
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("revolutions = 2147483647"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1e+10"), std::string::npos) << e.what();
  }
}

// ---- Item 9: limits in the configuration reader
// ------------------------------------------------------------

TEST(ConfigurationLimits, RevolutionsAndSampleRateHaveAnUpperLimitNamedInTheRefusal) {
  const auto refused = [](const std::string& line, const std::string& expect) {
    try {
      (void)parse_scenario("[test]\n" + line + "\n", "c.toml");
      ADD_FAILURE() << line << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
    }
  };
  refused("revolutions = 2147483647", "<= 100000000");
  refused("sample_rate_hz = 1e9", "sample_rate_hz must be > 0 and <= 1e+06");
  EXPECT_EQ(parse_scenario("[test]\nrevolutions = 100000000\n", "c.toml").test.revolutions, 100000000);
}

// ---- Item 9: the plan's cost does not grow with the test's length -----------------------------------------

/// The walking route: every sample of the planned dwell through the reducer's accumulator.
Eigen::MatrixXd walked_covariance(const Dwell& d, const ReduceOptions& options) {
  DwellAccumulator acc(options, d.gammas_rad, d.is_static, 1, d.planned_duration_s, false);
  const double zero = 0.0;
  for (std::size_t i = 0; i < d.samples; ++i) {
    const double t = d.time_of_sample(i);
    acc.add(t, -d.counter.at(t, d.first_time_s), &zero);
  }
  return acc.white_noise_covariance();
}

TEST(PlanCost, ClosedFormDwellCovarianceEqualsTheWalkOverEverySample) {
  // The default scenario, a static set, a negative rate with a non-integer count of samples per revolution, a
  // counter-rate mismatch, and a fit without drift or of another order.
  std::vector<std::pair<Scenario, ReduceOptions>> cases;
  cases.emplace_back(default_scenario(), ReduceOptions{});
  Scenario odd = default_scenario();
  odd.test.rates_rad_s = {-7.3, 0.0};
  odd.test.sample_rate_hz = 173.0;
  odd.test.revolutions = 17;
  odd.errors.counter_rate_mismatch_rad_s = 1e-3;
  cases.emplace_back(odd, ReduceOptions{});
  ReduceOptions no_drift;
  no_drift.linear_drift = false;
  no_drift.harmonic_order = 5;
  cases.emplace_back(odd, no_drift);
  for (const auto& [scenario, options] : cases) {
    const Reduction r = planned_reduction(scenario);
    for (const Dwell& d : r.dwells) {
      const Eigen::MatrixXd closed = dwell_white_noise_covariance(d, options);
      const Eigen::MatrixXd walked = walked_covariance(d, options);
      ASSERT_EQ(closed.rows(), walked.rows());
      // Rounding of the ~1e5-term sums: 1e-9 of the largest entry.
      EXPECT_LT((closed - walked).cwiseAbs().maxCoeff(), 1e-9 * walked.cwiseAbs().maxCoeff())
          << "closed\n"
          << closed << "\nwalked\n"
          << walked;
    }
  }
}

TEST(PlanCost, BoundedModelEvaluationsAgreeWithEveryRevolutionsOnALongTest) {
  // 1500 revolutions: the model terms' evaluations are capped at kMaxModelSamplesPerDwell per dwell (a stride
  // longer than a revolution) instead of 32 per revolution. Stated error (docs/calibration.md): every reduced
  // model term within 1e-7 of its scale (omega in deg/h, regressors in g^n), i.e. far below any noise.
  Scenario s = default_scenario();
  s.test.revolutions = std::getenv("GYROCAL_SANITIZED") ? 1200 : 1500;
  const Reduction r = planned_reduction(s);
  ASSERT_GT(r.dwells.front().samples / 3, kMaxModelSamplesPerDwell);  // the cap is in force
  const CentrifugeModel model = s.model();
  const std::vector<PositionModelTerms> capped =
      reduce_model_terms(r, model, ReduceOptions{}, kMaxModelSamplesPerDwell);
  const std::vector<PositionModelTerms> every = reduce_model_terms(r, model, ReduceOptions{}, 0);
  ASSERT_EQ(capped.size(), every.size());
  for (std::size_t i = 0; i < every.size(); ++i) {
    EXPECT_NEAR(capped[i].omega_exact_deg_h, every[i].omega_exact_deg_h, 1e-7 * 50.0) << i;
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
      EXPECT_NEAR(capped[i].regressors_exact[k], every[i].regressors_exact[k],
                  1e-7 * std::max(1.0, std::abs(every[i].regressors_exact[k])))
          << i << " " << k;
  }
}

TEST(PlanCost, DefaultPredictionIsUnchangedByTheClosedForm) {
  // On the default scenario the capped model terms are the uncapped ones (8500 evaluations per dwell) and the
  // closed-form covariance equals the walk (above): the prediction's stds equal the walking route's to 1e-9.
  const Scenario s = default_scenario();
  Reduction r = planned_reduction(s);
  const ReduceOptions options;
  const double sample_std = white_noise_sample_std_deg_h(s.noise, s.test.sample_rate_hz);
  const Eigen::MatrixXd cov = predicted_position_covariance(r, options, sample_std);
  for (std::size_t i = 0; i < r.positions.size(); ++i) {
    const ReducedPosition& p = r.positions[i];
    const Eigen::MatrixXd walked = walked_covariance(r.dwells[static_cast<std::size_t>(p.dwell)], options);
    const double expected = std::sqrt(walked(p.gamma_slot, p.gamma_slot)) * sample_std;
    EXPECT_NEAR(std::sqrt(cov(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i))), expected,
                1e-9 * expected);
  }
}

// ---- Item 5: the record's metadata against the configuration ----------------------------------------------

class Metadata : public Messages {
 protected:
  void SetUp() override {
    Messages::SetUp();
    const Outcome o = run("simulate --out " + path("r.csv").string() + " --config " +
                          config("base.toml", {{"revolutions", "3"}}));
    ASSERT_EQ(o.status, 0) << o.err;
  }
};

TEST_F(Metadata, AConfigurationThatMakesTheCalibrationWrongIsRefusedByName) {
  const std::vector<std::pair<std::string, std::string>> cases = {{"radius_m", "2.0"},
                                                                  {"latitude_deg", "45.0"},
                                                                  {"heading_deg", "10.0"},
                                                                  {"gravity_m_s2", "9.81"},
                                                                  {"earth_rate_rad_s", "7e-05"},
                                                                  {"rates_rad_s", "[9.8]"},
                                                                  {"beta_deg", "[0.0, 180.0, 90.0, 271.0]"}};
  for (const auto& [key, value] : cases) {
    fs::remove(path("out.json"));
    const std::string cfg = config(key + ".toml", {{"revolutions", "3"}, {key, value}});
    const Outcome o = run("calibrate " + path("r.csv").string() + " --config " + cfg + " --json " +
                          path("out.json").string());
    EXPECT_EQ(o.status, 1) << key << ": " << o.out;
    EXPECT_NE(o.err.find("the record's " + key + " = "), std::string::npos) << key << ": " << o.err;
    EXPECT_NE(o.err.find(cfg), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(path("out.json"))) << key;
  }
}

TEST_F(Metadata, OtherDisagreementsWarnOnStandardErrorAndInTheResult) {
  const std::string cfg = config("settle.toml", {{"revolutions", "3"}, {"settle_s", "1.5"}});
  const Outcome o = run("calibrate " + path("r.csv").string() + " --config " + cfg + " --json " +
                        path("out.json").string());
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.err.find("warning: the record's settle_s = 2 differs from 1.5 in " + cfg), std::string::npos)
      << o.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(path("out.json")));
  bool found = false;
  for (const auto& w : j["warnings"])
    found = found || w.get<std::string>().find("settle_s = 2") != std::string::npos;
  EXPECT_TRUE(found) << j["warnings"];
  // The configuration it was recorded with: no metadata warning.
  const Outcome same = run("calibrate " + path("r.csv").string() + " --config " + path("base.toml").string());
  ASSERT_EQ(same.status, 0) << same.err;
  EXPECT_EQ(same.err.find("the record's"), std::string::npos) << same.err;
}

}  // namespace
}  // namespace gyrocal
