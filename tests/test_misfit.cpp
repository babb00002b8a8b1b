// A misfit is never reported with a tiny std (docs/calibration.md, "When the residuals misfit"): the records
// a lab's set-up gets wrong are refused with the cause named; a record with a modest unmodelled effect is
// accepted with honest uncertainties, and a large one has its std scaled, still honest.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/misfit.hpp"
#include "gyrocal/model/machine_errors.hpp"
#include "gyrocal/result/calibration_json.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

/// How a lab's set-up changes what a rig records: a sample as simulated -> as recorded.
using Fault = std::function<void(RecordSample&)>;

struct Outcome {
  bool refused = false;
  std::string message;
  CalibrationResult result;
};

/// `s` simulated with `seed`, changed by `fault`, reduced and identified as calibrate does (the output's
/// range kept as calibrate_record keeps it).
Outcome calibrate_with(const Scenario& s, std::uint64_t seed, const Fault& fault, CalibrationOptions o = {}) {
  Reducer reducer(s.test, o.reduce, "faulty.csv", s.centrifuge.rate_rad_s);
  SimulationOptions so;
  so.seed = seed;
  simulate(s, so, [&](RecordSample x) {
    if (fault) fault(x);
    o.output.range.push(x.outputs[0]);
    reducer.push(x);
  });
  const Reduction r = reducer.finish();
  Outcome out;
  try {
    out.result = identify(r, reduce_model_terms(r, s.model(), o.reduce), s.model(), o);
  } catch (const Error& e) {
    out.refused = true;
    out.message = e.what();
  }
  return out;
}

/// The issue's scenario: the default one with 30 revolutions per dwell.
Scenario default_30() {
  Scenario s = default_scenario();
  s.test.revolutions = 30;
  return s;
}

/// The largest |estimate - truth| / std over the identifiable coefficients.
double worst_z(const Scenario& s, const CalibrationResult& r) {
  double worst = 0.0;
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
    if (r.coefficients[k].identifiable)
      worst = std::max(worst, std::abs(r.coefficients[k].value - s.gyro.values[k]) / r.coefficients[k].std);
  return worst;
}

double std_of(const std::vector<double>& z) {
  double mean = 0, var = 0;
  for (double x : z) mean += x;
  mean /= static_cast<double>(z.size());
  for (double x : z) var += (x - mean) * (x - mean);
  return std::sqrt(var / static_cast<double>(z.size() - 1));
}

TEST(MisfitPValue, AgreesWithTheClosedFormsOfItsDistributions) {
  // chi-squared with 2 dof: P(X >= x) = exp(-x/2); with 1 dof: erfc(sqrt(x/2)).
  for (double x : {0.1, 1.0, 5.0, 20.0, 60.0}) {
    EXPECT_NEAR(misfit_p_value(x, 2, std::numeric_limits<double>::infinity()), std::exp(-x / 2),
                1e-12 + 1e-10 * std::exp(-x / 2))
        << x;
    EXPECT_NEAR(misfit_p_value(x, 1, std::numeric_limits<double>::infinity()), std::erfc(std::sqrt(x / 2)),
                1e-12 + 1e-10 * std::erfc(std::sqrt(x / 2)))
        << x;
  }
  // F(2, n): P(F >= f) = (1 + 2 f / n)^(-n/2); chi2 = 2 f.
  for (double n : {3.0, 10.0, 57.5, 400.0})
    for (double f : {0.2, 1.0, 4.0, 30.0}) {
      const double expected = std::pow(1 + 2 * f / n, -n / 2);
      EXPECT_NEAR(misfit_p_value(2 * f, 2, n), expected, 1e-12 + 1e-9 * expected) << n << " " << f;
    }
  // Many weight dof: the F tends to chi-squared.
  EXPECT_NEAR(misfit_p_value(14.0, 7, 1e6), misfit_p_value(14.0, 7, std::numeric_limits<double>::infinity()),
              1e-4);
  EXPECT_EQ(misfit_p_value(1e30, 7, 100.0), 0.0);
  EXPECT_EQ(misfit_p_value(3.0, 0, 100.0), 1.0);
}

TEST(Misfit, TheIssuesFourRecordsAreRefusedWithTheirCauseNamed) {
  // The default scenario, 30 revolutions: each record least squares and closed forms. Before, each gave std
  // of a good record on estimates hundreds of std off (issue 18).
  const Scenario s = default_30();
  struct Case {
    std::string name;
    Fault fault;
    std::vector<std::string> says;
  };
  const std::vector<Case> cases = {
      {"sign flipped",
       [](RecordSample& x) { x.outputs[0] = -x.outputs[0]; },
       {"sign is flipped", "[record] output_scale_per_deg_h = -1 ", "chi2 = "}},
      {"deg/s where deg/h is configured",
       [](RecordSample& x) { x.outputs[0] /= 3600.0; },
       {"the output is in deg/s", "[record] output_scale_per_deg_h = 0.000277778 "}},
      {"clipped at 15 deg/h",
       [](RecordSample& x) { x.outputs[0] = std::clamp(x.outputs[0], -15.0, 15.0); },
       {"saturated or clipped", "15 deg/h"}},
      {"dead sensor writing 0.0", [](RecordSample& x) { x.outputs[0] = 0.0; }, {"dead or disconnected"}},
  };
  for (const Case& c : cases)
    for (Method m : {Method::kLeastSquares, Method::kClosedForm}) {
      CalibrationOptions o;
      o.method = m;
      const Outcome out = calibrate_with(s, 7, c.fault, o);
      if (!out.refused) {
        // Accepted only with every identifiable coefficient within 4.5 stated std of the truth.
        EXPECT_LT(worst_z(s, out.result), 4.5) << c.name << " " << to_string(m);
        continue;
      }
      for (const std::string& part : c.says)
        EXPECT_NE(out.message.find(part), std::string::npos) << c.name << ": " << out.message;
    }
  // The sign and the unit must be named, not merely refused.
  for (std::size_t k = 0; k < 2; ++k)
    EXPECT_TRUE(calibrate_with(s, 8, cases[k].fault).refused) << cases[k].name;
}

TEST(Misfit, AConstantOutputIsADeadSensorWhateverItsValue) {
  const Outcome out = calibrate_with(default_30(), 3, [](RecordSample& x) { x.outputs[0] = 5.0; });
  ASSERT_TRUE(out.refused);
  EXPECT_NE(out.message.find("constant 5 deg/h"), std::string::npos) << out.message;
}

TEST(Misfit, DriftPlusRateFitsASignAsAScaleFactorAndIsStillRefused) {
  // drift+rate would fit a flipped sign as e = -2e6 ppm with a perfect chi2: a scale-factor error no gyro
  // has.
  Scenario s = default_scenario();
  s.gyro_rate = {150.0, -25.0, 40.0};
  s.test.rates_rad_s = {9.9, 4.95};
  s.test.counter_rate_offsets_rad_s = {0.0, 0.25, -0.25};
  s.test.sample_rate_hz = 50.0;
  s.test.revolutions = 8;
  s.test.settle_s = 1.0;
  CalibrationOptions o;
  o.gyro_model = GyroModel::kDriftRate;
  const Outcome clean = calibrate_with(s, 3, nullptr, o);
  ASSERT_FALSE(clean.refused) << clean.message;
  EXPECT_EQ(clean.result.misfit.scale, 1.0);
  const Outcome flipped = calibrate_with(
      s, 3, [](RecordSample& x) { x.outputs[0] = -x.outputs[0]; }, o);
  ASSERT_TRUE(flipped.refused);
  EXPECT_NE(flipped.message.find("scale-factor error is -2"), std::string::npos) << flipped.message;
  EXPECT_NE(flipped.message.find("output_scale_per_deg_h = -1 "), std::string::npos) << flipped.message;
}

TEST(Misfit, ASelfCalibrationNamesAFlippedSignRatherThanFailingToConverge) {
  Scenario s = default_30();
  s.test.rates_rad_s = {9.9, 4.95};
  CalibrationOptions o;
  o.estimate =
      parse_machine_error_names({"counter_perpendicularity_x", "counter_perpendicularity_y"}, "test");
  const Outcome out = calibrate_with(
      s, 4, [](RecordSample& x) { x.outputs[0] = -x.outputs[0]; }, o);
  ASSERT_TRUE(out.refused);
  EXPECT_NE(out.message.find("sign is flipped"), std::string::npos) << out.message;
}

TEST(Misfit, TheCounterPlatformCountedTheOtherWayIsNamedOrFitsConsistently) {
  // The outputs at gamma 90 and 270 deg exchanged in every dwell, as a counter angle counted the other way
  // puts them: written out here, not with the library's transform. On the 16 positions of one speed the
  // coefficients absorb it (the sin-gamma terms change sign): the fit is consistent and no test of the
  // residuals can see it (docs/calibration.md); when it does misfit, the cause must be the counter angle.
  const Scenario s = default_30();
  Reducer reducer(s.test, {}, "swapped.csv", s.centrifuge.rate_rad_s);
  SimulationOptions so;
  so.seed = 5;
  simulate(s, so, [&](const RecordSample& x) { reducer.push(x); });
  Reduction r = reducer.finish();
  const auto at = [&](int dwell, double gamma_deg) -> ReducedPosition& {
    for (ReducedPosition& p : r.positions)
      if (p.dwell == dwell && std::abs(p.gamma_rad * kRadToDeg - gamma_deg) < 1e-6) return p;
    throw Error("no such position");
  };
  for (std::size_t d = 0; d < r.dwells.size(); ++d) {
    ReducedPosition& a = at(static_cast<int>(d), 90.0);
    ReducedPosition& b = at(static_cast<int>(d), 270.0);
    std::swap(a.mean, b.mean);
    std::swap(r.dwells[d].output.value[static_cast<std::size_t>(a.gamma_slot)],
              r.dwells[d].output.value[static_cast<std::size_t>(b.gamma_slot)]);
  }
  try {
    const CalibrationResult c = identify(r, reduce_model_terms(r, s.model(), {}), s.model(), {});
    EXPECT_GE(c.misfit.p_value, 1e-3);
    EXPECT_EQ(c.misfit.scale, 1.0);
    std::printf("gamma mirrored: accepted, chi2/dof %.3g, worst |estimate - truth| / std %.3g\n",
                c.chi2 / c.dof, worst_z(s, c));
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("counter_angle_column"), std::string::npos) << e.what();
  }
}

TEST(Misfit, AModestTemperatureDriftIsAcceptedWithHonestUncertainties) {
  // The bias drifts 0.5 deg/h per hour across the test (a temperature drift the model lacks): no record is
  // refused, and over 100 seeds (the least the issue asks; the spread of a std over 100 is about 0.07)
  // (estimate - truth) / std has a standard deviation <= 1.15 for every identifiable coefficient.
  const Scenario s = default_30();
  const Fault drift = [](RecordSample& x) { x.outputs[0] += 0.5 / 3600.0 * x.time_s; };
  const int seeds = 100;
  std::vector<std::vector<double>> z(kNumGyroCoefficients);
  int scaled = 0;
  for (int seed = 0; seed < seeds; ++seed) {
    const Outcome out = calibrate_with(s, 2000 + static_cast<std::uint64_t>(seed), drift);
    ASSERT_FALSE(out.refused) << out.message;
    scaled += out.result.misfit.scale > 1.0;
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
      if (out.result.coefficients[k].identifiable)
        z[k].push_back((out.result.coefficients[k].value - s.gyro.values[k]) /
                       out.result.coefficients[k].std);
  }
  std::printf("temperature drift 0.5 deg/h per hour: %d of %d records scaled\n", scaled, seeds);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    if (z[k].empty()) continue;
    const double sd = std_of(z[k]);
    std::printf("  std of z for %s: %.3f\n", std::string(kCoefficientNames[k]).c_str(), sd);
    EXPECT_LE(sd, 1.15) << kCoefficientNames[k];
  }
}

TEST(Misfit, ALargeDriftScalesEveryStdAndSaysSo) {
  // 20 deg/h per hour: every record misfits beyond chance, no set-up mistake explains it, so std is scaled by
  // sqrt(chi2/dof), stated in the warning and the JSON, and stays honest (conservative: the drift is smooth).
  const Scenario s = default_30();
  const Fault drift = [](RecordSample& x) { x.outputs[0] += 20.0 / 3600.0 * x.time_s; };
  std::vector<double> z;
  for (int seed = 0; seed < 20; ++seed) {
    const Outcome out = calibrate_with(s, 3000 + static_cast<std::uint64_t>(seed), drift);
    ASSERT_FALSE(out.refused) << out.message;
    const CalibrationResult& r = out.result;
    ASSERT_TRUE(r.misfit.tested);
    EXPECT_LT(r.misfit.p_value, 1e-3);
    EXPECT_NEAR(r.misfit.scale, std::sqrt(r.chi2 / r.dof), 1e-12 * r.misfit.scale);
    const nlohmann::json j = calibration_to_json(r);
    EXPECT_EQ(j.at("misfit").at("std_scale").get<double>(), r.misfit.scale);
    bool warned = false;
    for (const std::string& w : r.warnings)
      warned |= w.find("every std is multiplied by") != std::string::npos;
    EXPECT_TRUE(warned);
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
      if (r.coefficients[k].identifiable)
        z.push_back((r.coefficients[k].value - s.gyro.values[k]) / r.coefficients[k].std);
  }
  double ss = 0;
  for (double x : z) ss += x * x;
  const double rms = std::sqrt(ss / static_cast<double>(z.size()));
  std::printf("temperature drift 20 deg/h per hour, scaled std: RMS of z %.3f\n", rms);
  EXPECT_LT(rms, 1.15);
}

TEST(Misfit, AGoodRecordsStdIsTheWeightsOwn) {
  // The clean record: consistent, nothing scaled, the JSON says so.
  const Outcome out = calibrate_with(default_30(), 7, nullptr);
  ASSERT_FALSE(out.refused) << out.message;
  EXPECT_TRUE(out.result.misfit.tested);
  EXPECT_GE(out.result.misfit.p_value, 1e-3);
  EXPECT_EQ(out.result.misfit.scale, 1.0);
  const nlohmann::json j = calibration_to_json(out.result);
  EXPECT_EQ(j.at("misfit").at("std_scale").get<double>(), 1.0);
}

TEST(MisfitCli, AFlippedSignIsRefusedWithNoResultFileAndTheKeyThatFixesIt) {
  const std::filesystem::path dir = test::fresh_test_folder("gyrocal-misfit");
  Scenario s = default_scenario();
  s.test.revolutions = 12;
  s.test.sample_rate_hz = 100;
  s.test.settle_s = 1;
  {
    std::ofstream(dir / "test.toml") << scenario_to_toml(s);
    // The record as simulate writes it, with every output's sign flipped.
    ASSERT_EQ(test::run_cli("simulate --config " + (dir / "test.toml").string() + " --out " +
                                (dir / "good.csv").string(),
                            dir)
                  .status,
              0);
    std::ifstream in(dir / "good.csv");
    std::ofstream out(dir / "flipped.csv");
    std::string line;
    while (std::getline(in, line)) {
      if (!line.empty() && (std::isdigit(static_cast<unsigned char>(line[0])) || line[0] == '-')) {
        const std::size_t comma = line.rfind(',');
        const std::string value = line.substr(comma + 1);
        line = line.substr(0, comma + 1) + (value[0] == '-' ? value.substr(1) : "-" + value);
      }
      out << line << "\n";
    }
  }
  const test::CliOutcome o =
      test::run_cli("calibrate " + (dir / "flipped.csv").string() + " --config " +
                        (dir / "test.toml").string() + " --json " + (dir / "result.json").string(),
                    dir);
  EXPECT_NE(o.status, 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "result.json"));
  EXPECT_NE(o.err.find("output_scale_per_deg_h = -1"), std::string::npos) << o.err;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace gyrocal
