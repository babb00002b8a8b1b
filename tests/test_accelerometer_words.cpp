// An accelerometer's result in its own words (docs/accelerometer.md): no gyro word, no deg/h and no drift in
// what gyrocal says about an accelerometer (its help, init's comments, its tables and JSON), positions keyed
// for any sensor with their unit, correlations and messages by coefficient names, the radius in microns where
// people read it, K1 in the unit the lab names ([record] output_unit), the coefficients in the IEEE table's
// order, and IEEE Std 1293's misalignment convention against gyrocal's keys.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/sensor/accelerometer.hpp"
#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

/// A gyro's word: "gyro" as a word ("gyro", "gyro's", "[gyro.noise]"), not "gyrocal".
const std::regex kGyroWord(R"(\bgyro\b)", std::regex::icase);

/// The lines of `text` that hold `pattern`.
std::vector<std::string> lines_with(const std::string& text, const std::regex& pattern) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (std::regex_search(line, pattern)) out.push_back(line);
  return out;
}

/// The small two-speed accelerometer test of tests/test_accelerometer_calibrate.cpp (a static set, 6 and 12
/// rad/s, four beta, 8 revolutions at 50 Hz), noise-free, with K1 = `k1` and a 30 um longer arm.
Scenario small_accelerometer(double k1) {
  Scenario s = default_accelerometer_scenario();
  s.accelerometer.noise = AccelerometerNoise{};
  s.accelerometer.coefficients.values[static_cast<std::size_t>(AccelCoefficient::K1)] = k1;
  s.test.rates_rad_s = {0.0, 6.0, 12.0};
  s.centrifuge.rate_rad_s = 6.0;
  s.test.revolutions = 8;
  s.test.sample_rate_hz = 50.0;
  s.test.static_hold_s = 2.0;
  s.errors.radius_error_m = 30e-6;
  return s;
}

/// Writes `toml` to dir/name and returns its path.
std::string write_file(const std::filesystem::path& dir, const std::string& name, const std::string& toml) {
  std::ofstream out(dir / name);
  out << toml;
  return (dir / name).string();
}

TEST(AccelerometerWords, HelpNamesBothSensorsWhereItNamesTheGyro) {
  // The help cannot know the sensor: where it names the gyro (or its drift) it names the accelerometer too.
  const auto dir = test::fresh_test_folder("awords");
  for (const std::string sub : {"", "calibrate", "plan", "inputs", "simulate", "sensitivity", "montecarlo",
                                "noise", "init", "demo"}) {
    const test::CliOutcome o = test::run_cli(sub + " --help", dir);
    ASSERT_EQ(o.status, 0) << sub << o.err;
    // --gyro-model's own line (its name and values) is the option's; its description names the accelerometer.
    for (const std::string& line : lines_with(o.out, std::regex(R"(\bgyro\b(?!-model)|drift)")))
      if (line.find("--gyro-model TEXT") == std::string::npos) {
        EXPECT_NE(line.find("accelerometer"), std::string::npos) << "gyrocal " << sub << " --help: " << line;
      }
    EXPECT_EQ(o.out.find("deg/h"), std::string::npos) << sub;
  }
  EXPECT_NE(test::run_cli("--help", dir).out.find("a gyroscope or an accelerometer"), std::string::npos);
  EXPECT_EQ(test::run_cli("calibrate --help", dir).out.find("identify the drift coefficients"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(AccelerometerWords, InitCommentsNameTheAccelerometersAxesAndTheGyrosStayTheGyros) {
  const auto dir = test::fresh_test_folder("awords");
  const test::CliOutcome a = test::run_cli("init --sensor accelerometer -", dir);
  ASSERT_EQ(a.status, 0) << a.err;
  std::istringstream in(a.out);
  int comments = 0;
  for (std::string line; std::getline(in, line);) {
    const auto hash = line.find('#');
    if (hash == std::string::npos) continue;
    const std::string comment = line.substr(hash);
    ++comments;
    // [sensor] kind names the choices, the gyro among them; nothing else speaks of a gyro.
    if (line.rfind("kind = ", 0) != 0) {
      EXPECT_FALSE(std::regex_search(comment, kGyroWord)) << line;
    }
    EXPECT_EQ(comment.find("deg/h"), std::string::npos) << line;
    EXPECT_EQ(comment.find("drift"), std::string::npos) << line;  // (the key linear_drift is a key)
    EXPECT_EQ(comment.find("I, O, S"), std::string::npos) << line;
  }
  EXPECT_GT(comments, 100);
  EXPECT_NE(a.out.find("mounting misalignment about i, p, o"), std::string::npos);
  EXPECT_NE(a.out.find("position-platform axes (i, p, o at beta = 0)"), std::string::npos);
  EXPECT_NE(a.out.find("output and encoder sampling rate"), std::string::npos);
  EXPECT_NE(a.out.find("IEEE 1293's delta_o"), std::string::npos);
  EXPECT_NE(a.out.find("# output_unit = \"g\""), std::string::npos);
  // It still reads back as the default accelerometer scenario.
  EXPECT_EQ(scenario_to_toml(parse_scenario(a.out, "a.toml")), a.out);
  // The gyro's file keeps its own words.
  const test::CliOutcome g = test::run_cli("init -", dir);
  ASSERT_EQ(g.status, 0) << g.err;
  EXPECT_NE(g.out.find("gyro mounting misalignment about I, O, S"), std::string::npos);
  EXPECT_NE(g.out.find("gyro and encoder sampling rate"), std::string::npos);
  EXPECT_EQ(g.out.find("output_unit"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(AccelerometerWords, APartialPlansScaleCombinationIsInK1sUnit) {
  // beta = 0 and 90 only: K1 is not identifiable, K1 (1 - 1e-6 delta_o) is. Read through output_scale_per_g =
  // 2.5 (V), it is 2.5 (1 + 200e-6) = 2.5005 V/g, as K1 would be (before: 1.0002 "g/g").
  const auto dir = test::fresh_test_folder("awords");
  Scenario s = small_accelerometer(2.5);
  s.test.beta_rad = {0.0, kPi / 2};
  s.errors.radius_error_m = 0.0;
  const std::string truth = write_file(dir, "truth.toml", scenario_to_toml(s));
  ASSERT_EQ(test::run_cli("simulate --config " + truth + " --out " + (dir / "a.csv").string(), dir).status,
            0);
  const std::string config = write_file(
      dir, "rig.toml", scenario_to_toml(s) + "\n[record]\noutput_scale_per_g = 2.5\noutput_unit = \"V\"\n");
  const test::CliOutcome cal = test::run_cli("calibrate " + (dir / "a.csv").string() + " --config " + config +
                                                 " --json " + (dir / "a.json").string(),
                                             dir);
  ASSERT_EQ(cal.status, 0) << cal.err;
  const nlohmann::json j = nlohmann::json::parse(test::slurp(dir / "a.json"));
  bool found = false;
  for (const nlohmann::json& c : j.at("combinations")) {
    if (c.at("name") != "K1 (1 - 1e-6 delta_o)") continue;
    found = true;
    EXPECT_EQ(c.at("unit"), "V/g");
    EXPECT_NEAR(c.at("value").get<double>(), 2.5 * (1.0 + 200e-6), 1e-8);
  }
  EXPECT_TRUE(found) << j.at("combinations").dump();
  EXPECT_FALSE(j.at("coefficients").at("K1").at("identifiable").get<bool>());
  std::filesystem::remove_all(dir);
}

TEST(AccelerometerWords, OutputUnitNamesK1sUnitInTheJsonAndTheTables) {
  // A channel of 2.5 "V" per g: simulated with K1 = 2.5 (gyrocal's record then holds 2.5 per g), read with
  // [record] output_scale_per_g = 2.5 and output_unit = "V". K1 comes back 2.5 (noise-free, 1e-9) in V/g.
  const auto dir = test::fresh_test_folder("awords");
  const Scenario s = small_accelerometer(2.5);
  const std::string truth = write_file(dir, "truth.toml", scenario_to_toml(s));
  ASSERT_EQ(test::run_cli("simulate --config " + truth + " --out " + (dir / "a.csv").string(), dir).status,
            0);
  Scenario rig = s;
  rig.errors.radius_error_m = 0.0;  // the radius is estimated below
  const std::string config = write_file(
      dir, "rig.toml", scenario_to_toml(rig) + "\n[record]\noutput_scale_per_g = 2.5\noutput_unit = \"V\"\n");
  const test::CliOutcome cal =
      test::run_cli("calibrate " + (dir / "a.csv").string() + " --config " + config +
                        " --estimate radius_error --json " + (dir / "a.json").string(),
                    dir);
  ASSERT_EQ(cal.status, 0) << cal.err;
  const nlohmann::json j = nlohmann::json::parse(test::slurp(dir / "a.json"));
  const nlohmann::json& k1 = j.at("coefficients").at("K1");
  EXPECT_EQ(k1.at("unit"), "V/g");
  EXPECT_NEAR(k1.at("value").get<double>(), 2.5, 2.5e-9);
  // The table prints it; no placeholder unit is left anywhere.
  EXPECT_TRUE(std::regex_search(cal.out, std::regex(R"(\nK1 +[0-9.]+ .*  V/g\n)"))) << cal.out;
  EXPECT_EQ(cal.out.find("output/g"), std::string::npos);
  EXPECT_EQ(test::slurp(dir / "a.json").find("output/g"), std::string::npos);
  const test::CliOutcome plan = test::run_cli("plan --config " + config, dir);
  ASSERT_EQ(plan.status, 0) << plan.err;
  EXPECT_TRUE(std::regex_search(plan.out, std::regex(R"(\nK1 +[0-9.]+ .*  V/g\n)"))) << plan.out;
  // Without output_unit gyrocal's own record is in g: K1 in g/g.
  const std::string native = write_file(dir, "native.toml", scenario_to_toml(rig));
  const test::CliOutcome p0 = test::run_cli("plan --config " + native + " --json -", dir);
  ASSERT_EQ(p0.status, 0) << p0.err;
  EXPECT_EQ(nlohmann::json::parse(p0.out).at("coefficients").at("K1").at("unit"), "g/g");
  std::filesystem::remove_all(dir);
}

TEST(AccelerometerWords, OutputUnitIsAShortUnitName) {
  const std::string base = scenario_to_toml(default_accelerometer_scenario()) + "\n[record]\n";
  EXPECT_EQ(test::config_error(base + "output_unit = \"mV/V\"\n"), "");
  EXPECT_EQ(test::config_error(base + "output_unit = \"counts\"\n"), "");
  const std::string long_unit(limits::kOutputUnitBytes + 1, 'V');
  const std::string too_long = test::config_error(base + "output_unit = \"" + long_unit + "\"\n");
  EXPECT_NE(too_long.find("record.output_unit"), std::string::npos) << too_long;
  EXPECT_NE(too_long.find(std::to_string(limits::kOutputUnitBytes)), std::string::npos) << too_long;
  EXPECT_NE(too_long.find("rig.toml"), std::string::npos) << too_long;
  for (const std::string bad : {"m V", "V;g", "V\\n", "V,"}) {
    const std::string e = test::config_error(base + "output_unit = \"" + bad + "\"\n");
    EXPECT_NE(e.find("record.output_unit"), std::string::npos) << bad << ": " << e;
    EXPECT_NE(e.find("letters, digits"), std::string::npos) << bad << ": " << e;
  }
  // A non-ASCII name ("µV") is refused by the configuration reader, naming its line ("uV" is the unit).
  const std::string micro = test::config_error(base + "output_unit = \"\xC2\xB5V\"\n");
  EXPECT_NE(micro.find("rig.toml, line"), std::string::npos) << micro;
  // A layout's unit reads back from init's file.
  Scenario s = default_accelerometer_scenario();
  s.record = RecordLayout{};
  s.record->output_quantity = OutputQuantity::kSpecificForce;
  s.record->output_column = "U_acc";
  s.record->output_unit_name = "mA";
  const Scenario back = parse_scenario(scenario_to_toml(s), "a.toml");
  ASSERT_TRUE(back.record.has_value());
  EXPECT_EQ(back.record->output_unit_name, "mA");
  EXPECT_EQ(back.record->column_unit(), "mA");
}

TEST(AccelerometerWords, JsonAndTablesSpeakOfTheAccelerometerInTheIeeeOrder) {
  // calibrate --estimate radius_error on a noise-free record of an arm 30 um longer: the JSON's positions are
  // keyed mean, std_err, residual with unit g (no deg/h key), the coefficients in the IEEE table's order,
  // correlations by coefficient names; the console prints the radius in um.
  const auto dir = test::fresh_test_folder("awords");
  const Scenario s = small_accelerometer(1.0);
  const std::string truth = write_file(dir, "truth.toml", scenario_to_toml(s));
  ASSERT_EQ(test::run_cli("simulate --config " + truth + " --out " + (dir / "a.csv").string(), dir).status,
            0);
  Scenario rig = s;
  rig.errors.radius_error_m = 0.0;
  const std::string config = write_file(dir, "rig.toml", scenario_to_toml(rig));
  const test::CliOutcome cal =
      test::run_cli("calibrate " + (dir / "a.csv").string() + " --config " + config +
                        " --estimate radius_error --json " + (dir / "a.json").string(),
                    dir);
  ASSERT_EQ(cal.status, 0) << cal.err;
  const std::string text = test::slurp(dir / "a.json");
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(text);
  // The order: K0 K1 K2 K3 Kip Kio Kpo Kpp Koo delta_p delta_o, as the table (not Kio before Kip).
  std::vector<std::string> keys, expected;
  for (const auto& [key, value] : j.at("coefficients").items()) keys.push_back(key);
  for (const SensorParameter& p : kAccelerometerParameters) expected.emplace_back(p.name);
  EXPECT_EQ(keys, (std::vector<std::string>{"K0", "K1", "K2", "K3", "Kip", "Kio", "Kpo", "Kpp", "Koo",
                                            "delta_p", "delta_o"}));
  EXPECT_EQ(keys, expected);
  for (const nlohmann::ordered_json& p : j.at("positions")) {
    EXPECT_EQ(p.at("unit"), "g");
    EXPECT_TRUE(p.at("mean").is_number());
    EXPECT_TRUE(p.at("std_err").is_number());
    EXPECT_TRUE(p.at("residual").is_number());
    EXPECT_FALSE(p.contains("mean_deg_h"));
    EXPECT_FALSE(p.contains("std_err_deg_h"));
    EXPECT_FALSE(p.contains("residual_deg_h"));
  }
  // A static position at beta = 90 reads about +1 g (i up): the mean is in g.
  for (const nlohmann::ordered_json& p : j.at("positions")) {
    if (p.at("rate_rad_s") == 0.0 && std::abs(p.at("beta_deg").get<double>() - 90.0) < 1e-6) {
      EXPECT_NEAR(p.at("mean").get<double>(), 1.0, 1e-3);
    }
  }
  EXPECT_FALSE(std::regex_search(text, kGyroWord)) << "a gyro word in an accelerometer's JSON";
  EXPECT_EQ(text.find("deg_h"), std::string::npos);
  EXPECT_EQ(text.find("deg/h"), std::string::npos);
  EXPECT_EQ(text.find("drift"), std::string::npos);
  // The radius error's correlations: the eleven coefficients by name, none a product.
  const nlohmann::ordered_json& radius = j.at("machine_errors").at(0);
  EXPECT_EQ(radius.at("error"), "radius_error");
  EXPECT_NEAR(radius.at("value").get<double>(), 30e-6, 1e-9);
  std::vector<std::string> correlated;
  for (const auto& [key, value] : radius.at("correlations").items()) correlated.push_back(key);
  EXPECT_EQ(correlated, expected);
  // The radius trades against the scale factor: their correlation is strong and negative (a longer arm reads
  // as a larger scale at every speed; gravity alone pins K1).
  EXPECT_LT(radius.at("correlations").at("K1").get<double>(), -0.3);
  // The console: the radius in um (30 um, noise-free), its correlations by name; no gyro word, no deg/h.
  EXPECT_TRUE(
      std::regex_search(cal.out, std::regex(R"(radius_error +(30\.0|29\.9)[0-9]* ± \S+ +0 +um +K1 -0\.)")))
      << cal.out;
  EXPECT_EQ(cal.out.find("K1*"), std::string::npos) << cal.out;
  EXPECT_EQ(cal.out.find("0.00003"), std::string::npos) << cal.out;
  for (const std::string& line : lines_with(cal.out, kGyroWord)) ADD_FAILURE() << line;
  EXPECT_EQ(cal.out.find("deg/h"), std::string::npos) << cal.out;
  EXPECT_EQ(cal.out.find("drift"), std::string::npos) << cal.out;
  // plan: a collinear error is described by coefficient names too.
  const test::CliOutcome plan =
      test::run_cli("plan --config " + config + " --estimate radius_error,mount_misalignment", dir);
  ASSERT_EQ(plan.status, 0) << plan.err;
  EXPECT_NE(plan.out.find("collinear"), std::string::npos) << plan.out;
  EXPECT_EQ(plan.out.find("K1*"), std::string::npos) << plan.out;
  EXPECT_TRUE(std::regex_search(plan.out, std::regex(R"(radius_error +[-0-9.]+ ± [0-9.]+ +0 +um)")))
      << plan.out;
  std::filesystem::remove_all(dir);
}

TEST(AccelerometerWords, SensitivityAndMonteCarloKeepTheIeeeOrder) {
  const auto dir = test::fresh_test_folder("awords");
  Scenario s = small_accelerometer(1.0);
  s.uncertainty.radius_error_m = 5e-6;
  const std::string config = write_file(dir, "a.toml", scenario_to_toml(s));
  const std::vector<std::string> expected = {"K0",  "K1",  "K2",  "K3",      "Kip",    "Kio",
                                             "Kpo", "Kpp", "Koo", "delta_p", "delta_o"};
  const auto keys_of = [](const nlohmann::ordered_json& o) {
    std::vector<std::string> k;
    for (const auto& [key, value] : o.items()) k.push_back(key);
    return k;
  };
  const test::CliOutcome sens = test::run_cli("sensitivity --config " + config + " --json -", dir);
  ASSERT_EQ(sens.status, 0) << sens.err;
  const nlohmann::ordered_json js = nlohmann::ordered_json::parse(sens.out);
  EXPECT_EQ(keys_of(js.at("noise_std")), expected);
  EXPECT_EQ(keys_of(js.at("units")), expected);
  const test::CliOutcome mc = test::run_cli("montecarlo --trials 50 --config " + config + " --json -", dir);
  ASSERT_EQ(mc.status, 0) << mc.err;
  const nlohmann::ordered_json jm = nlohmann::ordered_json::parse(mc.out);
  EXPECT_EQ(keys_of(jm.at("coefficients")), expected);
  EXPECT_EQ(keys_of(jm.at("budget")), expected);
  EXPECT_EQ(jm.at("coefficients").at("K1").at("unit"), "g/g");
  std::filesystem::remove_all(dir);
}

TEST(AccelerometerWords, GyroPositionsKeepTheirEarlierKeysBesideTheNewOnes) {
  const auto dir = test::fresh_test_folder("awords");
  const std::string config = write_file(dir, "g.toml", test::short_test_toml());
  ASSERT_EQ(test::run_cli("simulate --config " + config + " --out " + (dir / "g.csv").string(), dir).status,
            0);
  const test::CliOutcome cal =
      test::run_cli("calibrate " + (dir / "g.csv").string() + " --config " + config + " --json -", dir);
  ASSERT_EQ(cal.status, 0) << cal.err;
  const nlohmann::json j = nlohmann::json::parse(cal.out);
  ASSERT_FALSE(j.at("positions").empty());
  for (const nlohmann::json& p : j.at("positions")) {
    EXPECT_EQ(p.at("unit"), "deg/h");
    EXPECT_EQ(p.at("mean"), p.at("mean_deg_h"));
    EXPECT_EQ(p.at("std_err"), p.at("std_err_deg_h"));
    EXPECT_EQ(p.at("residual"), p.at("residual_deg_h"));
  }
  std::filesystem::remove_all(dir);
}

TEST(IeeeMisalignmentConvention, RotationAboutOIsDeltaPAndAboutPIsMinusDeltaO) {
  // IEEE Std 1293 writes the misalignments as +deltaO a_p - deltaP a_o, each the input axis rotated about the
  // axis it is named for; gyrocal's delta_p and delta_o are the input axis tilted toward p and toward o.
  // Rotating the sensor's input axis by a small angle about o (about p) with Eigen's rotations, the reading
  // of a perfect sensor equals gyrocal's model with delta_p = +angle (delta_o = -angle) to second order.
  const Eigen::Vector3d i = Eigen::Vector3d::UnitX(), p = Eigen::Vector3d::UnitY(),
                        o = Eigen::Vector3d::UnitZ();
  ASSERT_TRUE(i.cross(p).isApprox(o));  // right-handed: i x p = o
  const double angle = 40e-6;           // rad
  for (const Eigen::Vector3d& f :
       {Eigen::Vector3d(0.3, -7.0, 1.0), Eigen::Vector3d(-12.0, 2.0, -0.5), Eigen::Vector3d(1.0, 1.0, 1.0)}) {
    for (const bool about_o : {true, false}) {
      const Eigen::Vector3d axis = about_o ? o : p;
      const Eigen::Vector3d turned = Eigen::AngleAxisd(angle, axis) * i;
      AccelerometerCoefficients c;  // K1 = 1, all else 0: a_i alone
      c[AccelCoefficient::K1] = 1.0;
      if (about_o)
        c[AccelCoefficient::delta_p] = angle * 1e6;  // urad: IEEE's deltaO is gyrocal's delta_p
      else
        c[AccelCoefficient::delta_o] = -angle * 1e6;  // IEEE's deltaP is minus gyrocal's delta_o
      EXPECT_NEAR(accelerometer_output(c, f), turned.dot(f), 1e-12 * f.norm() + f.norm() * angle * angle)
          << (about_o ? "about o" : "about p");
      // And not the other way round: the wrong sign misses by twice the term.
      if (about_o)
        c[AccelCoefficient::delta_p] = -angle * 1e6;
      else
        c[AccelCoefficient::delta_o] = angle * 1e6;
      EXPECT_GT(std::abs(accelerometer_output(c, f) - turned.dot(f)),
                1.5 * angle * std::abs(about_o ? f.y() : f.z()));
    }
  }
}

}  // namespace
}  // namespace gyrocal
