// The configuration's and the test plan's limits (issue 29; core/limits.hpp): every input that made the work
// unbounded is refused, before the work, with one sentence naming the file, line or key and the limit.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/identify/scenario_options.hpp"
#include "gyrocal/model/machine_errors.hpp"
#include "gyrocal/plan/positions.hpp"
#include "gyrocal/reduce/feasibility.hpp"
#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

/// The message of the Error that `run` throws ("" and a failure if it throws none).
template <class F>
std::string refusal(F run) {
  try {
    run();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted";
  return "";
}

void expect_words(const std::string& message, const std::vector<std::string>& words) {
  for (const std::string& w : words)
    EXPECT_NE(message.find(w), std::string::npos) << "'" << w << "' in: " << message;
}

std::string repeated(const std::string& part, std::size_t times, const std::string& separator) {
  std::string out;
  for (std::size_t i = 0; i < times; ++i) out += (i ? separator : "") + part;
  return out;
}

const std::string kLimitParts = std::to_string(limits::kConfigurationKeyParts);

// ---- D1: dotted keys, counted before the TOML library (whose recursion overflowed the stack)
// ----------------

TEST(ConfigurationKeyParts, FiftyThousandDottedPartsAreRefusedNamingTheLineAndTheLimit) {
  const std::string key = repeated("a", 50000, ".");
  for (const std::string& text :
       {key + " = 1\n", "[" + key + "]\n", "[[" + key + "]]\n", "site." + key + " = 1\n"}) {
    expect_words(refusal([&] { parse_scenario("# deep\n\n" + text, "deep.toml"); }),
                 {"deep.toml, line 3", kLimitParts, "dotted parts"});
  }
  // Around the dots, white space and quoted parts; in an inline table.
  expect_words(
      refusal([&] { parse_scenario("x = { " + repeated("'a'", 50000, " . ") + " = 1 }\n", "s.toml"); }),
      {"s.toml, line 1", kLimitParts});
}

TEST(ConfigurationKeyParts, TheLimitItselfAndDotsInStringsAndCommentsPass) {
  // As many parts as the limit: the TOML reader sees it (and refuses the unknown key).
  expect_words(refusal([&] {
                 parse_scenario(repeated("a", limits::kConfigurationKeyParts, ".") + " = 1\n", "s.toml");
               }),
               {"unknown key a"});
  // Dots inside quoted keys, strings and comments are not parts of a key.
  const std::string dots = repeated("a", 1000, ".");
  expect_words(refusal([&] { parse_scenario("\"" + dots + "\" = 1\n", "s.toml"); }), {"unknown key"});
  EXPECT_NO_THROW(parse_scenario("# " + dots + "\n[test]\nrevolutions = 10 # " + dots + "\n", "s.toml"));
  for (const std::string& value : {"'" + dots + "'", "\"" + dots + "\"", "'''\n" + dots + "\n" + dots + "'''",
                                   "\"\"\"\n" + dots + "\\\n" + dots + "\"\"\""}) {
    // A string value: refused, if at all, by the reader's rules for [record], not as a key.
    try {
      parse_scenario("[record]\ntime_column = " + value + "\n", "s.toml");
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).find("dotted parts"), std::string::npos) << e.what();
    }
  }
  // The values of a complete configuration (floats, strings) pass.
  EXPECT_NO_THROW(parse_scenario(scenario_to_toml(default_scenario()), "s.toml"));
  EXPECT_NO_THROW(parse_scenario(scenario_to_toml(default_accelerometer_scenario()), "s.toml"));
}

TEST(ConfigurationKeyParts, DeeplyNestedValuesAreRefusedByTheTomlReadersBound) {
  // toml++'s other recursion, into nested arrays and inline tables, is bounded by TOML_MAX_NESTED_VALUES.
  const std::size_t depth = 100000;
  expect_words(refusal([&] {
                 parse_scenario("a = " + std::string(depth, '[') + std::string(depth, ']') + "\n", "s.toml");
               }),
               {"s.toml, line 1", "nested"});
  expect_words(refusal([&] {
                 parse_scenario("a = " + repeated("{b=", depth, "") + "1" + std::string(depth, '}') + "\n",
                                "s.toml");
               }),
               {"s.toml, line 1", "nested"});
}

// ---- D3: harmonics
// ------------------------------------------------------------------------------------------

std::string series_text(const std::string& terms) {
  return "[centrifuge.errors]\nmain_wobble_y = [" + terms + "]\n";
}

std::string term(int harmonic) {
  return "{ harmonic = " + std::to_string(harmonic) + ", amplitude_arcsec = 1.0, phase_deg = 0.0 }";
}

TEST(HarmonicLimits, AHarmonicAboveTheLimitIsRefusedNamingTheKeyAndTheLimit) {
  EXPECT_NO_THROW(parse_scenario(series_text(term(limits::kHarmonic)), "h.toml"));
  expect_words(refusal([] { parse_scenario(series_text(term(1000000000)), "h.toml"); }),
               {"h.toml, line 2", "centrifuge.errors.main_wobble_y[0].harmonic",
                std::to_string(limits::kHarmonic), "1000000000"});
}

TEST(HarmonicLimits, ASeriesOfMoreTermsThanTheLimitIsRefused) {
  std::string terms;
  for (std::size_t i = 0; i <= limits::kHarmonicTerms; ++i) terms += (i ? ", " : "") + term(1);
  expect_words(
      refusal([&] { parse_scenario(series_text(terms), "h.toml"); }),
      {"h.toml, line 2", "centrifuge.errors.main_wobble_y",
       std::to_string(limits::kHarmonicTerms + 1) + " terms", std::to_string(limits::kHarmonicTerms)});
}

TEST(HarmonicLimits, EstimateRefusesAHarmonicAboveTheLimitAndTooManyNames) {
  EXPECT_NO_THROW(
      parse_machine_error_names({"counter_wobble_x:" + std::to_string(limits::kHarmonic)}, "--estimate"));
  expect_words(refusal([] { parse_machine_error_names({"counter_wobble_x:2147483647"}, "--estimate"); }),
               {"--estimate", "counter_wobble_x:2147483647", std::to_string(limits::kHarmonic)});
  std::vector<std::string> names;
  for (int n = 1; n <= 2000; ++n) names.push_back("counter_wobble_x:" + std::to_string(n));
  expect_words(refusal([&] { parse_machine_error_names(names, "--estimate"); }),
               {"--estimate", "2000", std::to_string(limits::kEstimatedErrors)});
  // Through the options every caller builds (the command line's --estimate, Python's estimate=).
  CalibrationChoices choices;
  choices.estimate = std::vector<std::string>{"counter_wobble_x:2147483647"};
  expect_words(refusal([&] { calibration_options(default_scenario(), choices); }), {"counter_wobble_x"});
}

// ---- D4: the test's positions ----------------------------------------------------------------------------

std::string values(std::size_t count, double step) {
  std::string out = "[";
  for (std::size_t k = 0; k < count; ++k) out += (k ? ", " : "") + toml_float(static_cast<double>(k) * step);
  return out + "]";
}

TEST(PositionLimits, AListOfMoreValuesThanTheLimitIsRefusedNamingTheKey) {
  const std::size_t n = limits::kPlanValuesPerList;
  for (const std::string key : {"beta_deg", "gamma_deg"}) {
    EXPECT_NO_THROW(parse_scenario("[test]\n" + key + " = " + values(n, 1.0) + "\n", "p.toml"));
    expect_words(
        refusal([&] { parse_scenario("[test]\n" + key + " = " + values(5760, 0.0625) + "\n", "p.toml"); }),
        {"p.toml, line 2", "test." + key, "5760", std::to_string(n)});
  }
  expect_words(
      refusal([&] { parse_scenario("[test]\nrates_rad_s = " + values(n + 1, 0.1) + "\n", "p.toml"); }),
      {"p.toml, line 2", "test.rates_rad_s", std::to_string(n)});
}

TEST(PositionLimits, MoreThanTheLimitOfPositionsInAllIsRefusedBeforeTheWork) {
  // 300 beta x 4 gamma = 1200 spinning positions, each list within its limit.
  const Scenario s = parse_scenario("[test]\nbeta_deg = " + values(300, 1.0) + "\n", "p.toml");
  EXPECT_EQ(test_positions(s.test).size(), 1200u);
  const std::string why = refusal([&] { check_test_feasible(s.test, s.reduce, s.centrifuge.rate_rad_s); });
  expect_words(why, {"1200 positions", "beta_deg", "gamma_deg", std::to_string(limits::kPositions)});
  expect_words(refusal([&] { predict_calibration(s, calibration_options(s, {})); }), {"1200 positions"});
  // The static set counts too: 2 rates (one of them 0) x 200 beta x 4 gamma = 1600.
  const Scenario t =
      parse_scenario("[test]\nrates_rad_s = [9.9, 0.0]\nbeta_deg = " + values(200, 1.0) + "\n", "p.toml");
  EXPECT_EQ(test_positions(t.test).size(), 1600u);
  // The default scenarios are far inside.
  EXPECT_LE(test_positions(default_scenario().test).size(), 64u);
  EXPECT_LE(test_positions(default_accelerometer_scenario().test).size(), 128u);
}

// ---- D9: more gamma than the harmonic fit's unknowns
// --------------------------------------------------------

// The values of a spinning dwell at 8 gamma are linear combinations of the 7 unknowns of an order-3 fit:
// their covariance is singular in exact arithmetic. At 10 revolutions it fails to factor, and the refusal
// names the two keys (it blamed "the record's scatter", in `plan`, which has no record); at 200 rounding lets
// it factor and the fit is that of order 4, so the test is not refused.
TEST(GammaLimits, AGyroTestOfMoreGammaThanTheHarmonicFitResolvesIsRefusedNamingBothKeys) {
  const std::string eight = "[test]\ngamma_deg = [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0]\n";
  const Scenario s = parse_scenario(eight + "revolutions = 10\n", "g8.toml");
  const std::string why = refusal([&] { predict_calibration(s, calibration_options(s, {})); });
  expect_words(why, {"[test] gamma_deg lists 8", "[reduce] harmonic_order = 3", "7 unknowns", "window"});
  EXPECT_EQ(why.find("scatter"), std::string::npos) << why;
  const Scenario long_dwells = parse_scenario(eight, "g8.toml");
  EXPECT_NO_THROW(predict_calibration(long_dwells, calibration_options(long_dwells, {})));
  // A higher order resolves them; the window mean has no such bound.
  const Scenario order4 =
      parse_scenario(eight + "revolutions = 10\n[reduce]\nharmonic_order = 4\n", "g8.toml");
  EXPECT_NO_THROW(predict_calibration(order4, calibration_options(order4, {})));
  const Scenario window =
      parse_scenario(eight + "revolutions = 10\n[calibration]\nreduction = \"window\"\n", "g8.toml");
  EXPECT_NO_THROW(predict_calibration(window, calibration_options(window, {})));
  // 7 gamma with order 3 pass; a static test's holds are read at one gamma each.
  const Scenario seven =
      parse_scenario("[test]\nrevolutions = 10\ngamma_deg = " + values(7, 50.0) + "\n", "g7.toml");
  EXPECT_NO_THROW(predict_calibration(seven, calibration_options(seven, {})));
  const Scenario held = parse_scenario(eight + "rates_rad_s = [0.0]\nstatic_hold_s = 10.0\n", "g8.toml");
  EXPECT_NO_THROW(predict_calibration(held, calibration_options(held, {})));
}

TEST(GammaLimits, TheAccelerometersEightGammaAreNotRefused) {
  // Its spinning dwells are reduced to 2 harmonic_order + 1 angles whatever gamma_deg lists.
  const Scenario a = default_accelerometer_scenario();
  ASSERT_EQ(a.test.gamma_rad.size(), 8u);
  EXPECT_NO_THROW(predict_calibration(a, calibration_options(a, {})));
}

TEST(GammaLimits, PlanRefusesNamingTheConfigurationAndBothKeys) {
  const std::filesystem::path dir = test::fresh_test_folder("gyrocal-limits");
  std::ofstream(dir / "g8.toml")
      << "[test]\nrevolutions = 10\ngamma_deg = [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0]\n";
  const test::CliOutcome o = test::run_cli("plan --config " + (dir / "g8.toml").string(), dir);
  EXPECT_EQ(o.status, 1) << o.err;
  expect_words(o.err, {"gyrocal: [test] gamma_deg lists 8", "[reduce] harmonic_order = 3"});
  EXPECT_EQ(o.err.find("scatter"), std::string::npos) << o.err;
  std::filesystem::remove_all(dir);
}

// ---- D15: a test of too many samples names the key that makes it long ----------------------------------

TEST(SampleLimits, TooManySamplesInTheStaticHoldsNamesStaticHoldS) {
  const Scenario s = parse_scenario("[test]\nrates_rad_s = [0.0]\nstatic_hold_s = 1e15\n", "h.toml");
  const std::string why = refusal([&] { check_test_feasible(s.test, s.reduce, s.centrifuge.rate_rad_s); });
  expect_words(why, {"static_hold_s = 1e+15", "1e+10"});
  EXPECT_EQ(why.find("revolutions"), std::string::npos) << why;
  // Long settle intervals name settle_s; long dwells still name revolutions.
  const Scenario settle = parse_scenario("[test]\nsettle_s = 1e15\n", "h.toml");
  expect_words(refusal([&] { check_test_feasible(settle.test, settle.reduce, 9.9); }), {"settle_s = 1e+15"});
  const Scenario spin = parse_scenario("[test]\nrevolutions = 100000000\n", "h.toml");
  expect_words(refusal([&] { check_test_feasible(spin.test, spin.reduce, 9.9); }),
               {"revolutions = 100000000"});
}

}  // namespace
}  // namespace gyrocal
