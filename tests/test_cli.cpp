// The command line as a user drives it: init, inputs, simulate, calibrate, plan; files, JSON and errors.
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include "support/cli_run.hpp"

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "support/independent_pose.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;

using Outcome = test::CliOutcome;
using test::slurp;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::fresh_test_folder("gyrocal-cli"); }
  void TearDown() override { fs::remove_all(dir_); }

  Outcome run(const std::string& args) const { return test::run_cli(args, dir_); }
  fs::path path(const std::string& name) const { return dir_ / name; }
  void write(const std::string& name, const std::string& text) const { std::ofstream(path(name)) << text; }
  /// Files in the folder besides the given ones (leftover temporaries, half-written outputs).
  std::vector<std::string> others(std::initializer_list<std::string> expected) const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string n = e.path().filename().string();
      if (std::find(expected.begin(), expected.end(), n) == expected.end()) out.push_back(n);
    }
    return out;
  }

  fs::path dir_;
};

TEST_F(Cli, InitWritesTheDefaultScenarioAndRefusesToOverwrite) {
  const Outcome first = run("init " + path("s.toml").string());
  ASSERT_EQ(first.status, 0) << first.err;
  const Scenario back = load_scenario(path("s.toml"));
  const Scenario def = default_scenario();
  EXPECT_EQ(scenario_to_toml(back), scenario_to_toml(def));
  EXPECT_EQ(back.gyro.values, def.gyro.values);
  EXPECT_EQ(back.errors.counter_perpendicularity_x_rad, def.errors.counter_perpendicularity_x_rad);

  write("s.toml", "# mine\n");
  const Outcome again = run("init " + path("s.toml").string());
  EXPECT_NE(again.status, 0);
  EXPECT_NE(again.err.find("--force"), std::string::npos) << again.err;
  EXPECT_EQ(slurp(path("s.toml")), "# mine\n");
  EXPECT_EQ(run("init --force " + path("s.toml").string()).status, 0);
  EXPECT_NE(slurp(path("s.toml")).find("[centrifuge.errors]"), std::string::npos);
  EXPECT_TRUE(others({"s.toml"}).empty());
}

TEST_F(Cli, InputsJsonMatchesTheIndependentPoseForARandomConfiguration) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 4; ++trial) {
    Scenario s = default_scenario();
    s.site.latitude_rad = 60 * kDegToRad * u(rng);
    s.centrifuge.radius_m = 1.5 + u(rng);
    s.centrifuge.rate_rad_s = 8 * u(rng);
    s.test.rates_rad_s = {s.centrifuge.rate_rad_s};  // one rate, one place (docs/interface.md)
    s.centrifuge.heading_rad = 3 * u(rng);
    s.centrifuge.initial_main_angle_rad = 3 * u(rng);
    s.errors.base_tilt_x_rad = 30 * kArcsecToRad * u(rng);
    s.errors.main_perpendicularity_y_rad = 30 * kArcsecToRad * u(rng);
    s.errors.main_runout_x_m.terms = {{2, 1e-5, 0.3}};
    s.errors.radius_error_m = 1e-4 * u(rng);
    s.errors.position_perpendicularity_x_rad = 30 * kArcsecToRad * u(rng);
    s.errors.position_wobble_z_rad.terms = {{1, 5 * kArcsecToRad, 1.0}};
    s.errors.position_angle_error_rad = 20 * kArcsecToRad * u(rng);
    s.errors.mount_misalignment_rad = Eigen::Vector3d(u(rng), u(rng), u(rng)) * 60 * kArcsecToRad;
    s.errors.lever_arm_m = Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.01;
    write("c.toml", scenario_to_toml(s));
    const double beta_deg = 180 * u(rng), t = 20 * std::abs(u(rng));
    const Outcome o = run("inputs --config " + path("c.toml").string() + " --beta-deg " +
                          std::to_string(beta_deg) + " --time-s " + std::to_string(t) + " --json -");
    ASSERT_EQ(o.status, 0) << o.err;
    const nlohmann::json j = nlohmann::json::parse(o.out);
    for (const char* key : {"time_s", "main_angle_deg", "counter_angle_deg", "beta_deg", "gamma_deg",
                            "omega_rad_s", "specific_force_g", "nominal"})
      EXPECT_TRUE(j.contains(key)) << key;
    // The configuration as the program read it, and the independent route at the same instant.
    const Scenario read = load_scenario(path("c.toml"));
    const SensorInputs fd = test_support::finite_difference_inputs(
        read.model(), read.centrifuge.rate_rad_s, std::stod(std::to_string(beta_deg)) * kDegToRad,
        std::stod(std::to_string(t)));
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(j["omega_rad_s"][k].get<double>(), fd.rate_rad_s[k], 1e-9) << trial << " " << k;
      EXPECT_NEAR(j["specific_force_g"][k].get<double>(), fd.specific_force_g[k], 1e-9) << trial << " " << k;
    }
  }
}

TEST_F(Cli, InputsAtGammaAndItsUsageErrors) {
  const Outcome o = run("inputs --beta-deg 90 --gamma-deg 270 --revolution 3 --json -");
  ASSERT_EQ(o.status, 0) << o.err;
  const nlohmann::json j = nlohmann::json::parse(o.out);
  EXPECT_NEAR(std::remainder(j["gamma_deg"].get<double>() - 270.0, 360.0), 0.0, 1e-7);
  EXPECT_GE(j["time_s"].get<double>(), 3 * 2 * kPi / 9.9);
  EXPECT_NE(run("inputs --beta-deg 0").status, 0);
  EXPECT_NE(run("inputs --beta-deg 0 --time-s 1 --gamma-deg 3").status, 0);
}

TEST_F(Cli, ABadConfigurationIsRefusedNamingKeyAndLine) {
  write("bad.toml", "[centrifuge]\nradius_m = -1.0\n");
  const Outcome o = run("plan --config " + path("bad.toml").string());
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("radius_m"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("line 2"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("bad.toml"), std::string::npos) << o.err;
}

using test::short_test_toml;

TEST_F(Cli, SimulateThenCalibrateWritesTheResultJsonOfTheInterface) {
  write("c.toml", short_test_toml());
  const std::string cfg = " --config " + path("c.toml").string();
  const Outcome sim = run("simulate" + cfg + " --out " + path("r.csv").string());
  ASSERT_EQ(sim.status, 0) << sim.err;
  EXPECT_NE(run("simulate" + cfg + " --out " + path("r.csv").string()).status, 0);  // no overwrite
  for (const char* method : {"closed-form", "least-squares"}) {
    const Outcome cal = run("calibrate " + path("r.csv").string() + cfg + " --method " + method +
                            " --compensation full --json " + path("res.json").string());
    ASSERT_EQ(cal.status, 0) << cal.err;
    const nlohmann::json j = nlohmann::json::parse(slurp(path("res.json")));
    for (const char* key : {"coefficients", "combinations", "positions", "alternatives", "method",
                            "compensation", "g_level", "warnings"})
      EXPECT_TRUE(j.contains(key)) << key;
    EXPECT_EQ(j["method"], method);
    EXPECT_EQ(j["compensation"], "full");
    EXPECT_EQ(j["coefficients"].size(), 10u);
    for (const char* name : {"dF", "dI", "dO", "dS", "dII", "dOO", "dSS", "dIO", "dIS", "dOS"}) {
      const auto& c = j["coefficients"][name];
      for (const char* key : {"value", "std", "unit", "identifiable"}) EXPECT_TRUE(c.contains(key)) << name;
    }
    EXPECT_FALSE(j["coefficients"]["dF"]["identifiable"].get<bool>());
    EXPECT_TRUE(j["coefficients"]["dF"]["value"].is_null());
    // The estimate is near the truth: dI = 0.5 within 5 standard uncertainties.
    const auto& di = j["coefficients"]["dI"];
    EXPECT_NEAR(di["value"].get<double>(), 0.5, 5 * di["std"].get<double>());
    std::set<std::string> names;
    for (const auto& c : j["combinations"]) {
      names.insert(c["name"].get<std::string>());
      EXPECT_EQ(c["coefficients"].size(), 10u);  // the combination actually estimated (docs/interface.md)
    }
    EXPECT_EQ(names, (std::set<std::string>{"dII-dSS", "dOO-dSS", "dF+(1+Ar^2)dSS"}));
    std::set<std::string> alts;
    for (const auto& a : j["alternatives"]) alts.insert(a["name"].get<std::string>());
    EXPECT_EQ(alts, (std::set<std::string>{"dI_1g", "dO_1g", "dS_1g", "dIS_b"}));
    ASSERT_EQ(j["positions"].size(), 16u);
    for (const char* key :
         {"index", "beta_deg", "gamma_deg", "rate_rad_s", "mean_deg_h", "std_err_deg_h", "samples"})
      EXPECT_TRUE(j["positions"][0].contains(key)) << key;
    EXPECT_EQ(j["positions"][8]["beta_deg"].get<double>(), 90.0);  // position 9 of docs/physics.md section 7
  }
  // The result is never written over the record.
  const Outcome over = run("calibrate " + path("r.csv").string() + cfg + " --json " + path("r.csv").string());
  EXPECT_NE(over.status, 0);
  EXPECT_EQ(slurp(path("r.csv")).rfind("# gyrocal-record 1", 0), 0u);
}

TEST_F(Cli, BadRecordsAreRefusedWithTheirLineAndNoOutputIsLeft) {
  write("c.toml", short_test_toml());
  const std::string cfg = " --config " + path("c.toml").string();
  ASSERT_EQ(run("simulate" + cfg + " --out " + path("r.csv").string()).status, 0);
  const std::string good = slurp(path("r.csv"));
  struct Case {
    std::string name, text, expect;
  };
  // A record cut off in the middle of a line; a row with a letter; a record without its last beta (the plan's
  // positions 13..16 missing); an empty file.
  const std::size_t cut = good.size() * 2 / 3;
  const std::size_t line_start = good.rfind('\n', cut) + 1;
  const std::string truncated = good.substr(0, line_start + 7);
  std::string lettered = good;
  lettered.replace(good.find('\n', good.find("time_s")) + 1, 1, "x");
  // The last quarter of the rows: beta = 270 (the plan's last beta) sits there.
  const std::size_t last_beta = good.find("\n", good.size() * 3 / 4);
  const std::vector<Case> cases = {
      {"truncated.csv", truncated, "line"},
      {"lettered.csv", lettered, "not a number"},
      {"short.csv", good.substr(0, last_beta + 1), "no usable dwell"},
      {"empty.csv", "", "empty"},
  };
  for (const Case& c : cases) {
    write(c.name, c.text);
    const Outcome o =
        run("calibrate " + path(c.name).string() + cfg + " --json " + path("out.json").string());
    EXPECT_EQ(o.status, 1) << c.name << ": " << o.err;
    EXPECT_NE(o.err.find(c.name), std::string::npos) << o.err;
    EXPECT_NE(o.err.find(c.expect), std::string::npos) << c.name << ": " << o.err;
    EXPECT_FALSE(fs::exists(path("out.json"))) << c.name;
  }
  EXPECT_TRUE(others({"c.toml", "r.csv", "truncated.csv", "lettered.csv", "short.csv", "empty.csv"}).empty());
}

TEST_F(Cli, PlanPredictsIdentifiabilityAndUncertainty) {
  const Outcome one = run("plan --json -");
  ASSERT_EQ(one.status, 0) << one.err;
  const nlohmann::json j = nlohmann::json::parse(one.out);
  EXPECT_EQ(j["rank"], 9);
  EXPECT_FALSE(j["coefficients"]["dSS"]["identifiable"].get<bool>());
  // White noise of 0.002 deg/sqrt(h) through 16 positions of 200 revolutions: a dI uncertainty of ~1e-3.
  const double s_di = j["coefficients"]["dI"]["std"].get<double>();
  EXPECT_GT(s_di, 3e-4);
  EXPECT_LT(s_di, 3e-3);
  write("two.toml", "[test]\nrates_rad_s = [9.9, 0.0]\nrevolutions = 20\n");
  const Outcome two = run("plan --json - --config " + path("two.toml").string());
  ASSERT_EQ(two.status, 0) << two.err;
  EXPECT_EQ(nlohmann::json::parse(two.out)["rank"], 10);
}

TEST_F(Cli, SensitivityAndMonteCarloTakeTheGyroModelAndWriteTheRateErrors) {
  // docs/contract.md: --gyro-model drift|drift+rate, default [calibration] gyro_model. With drift+rate the
  // JSON holds the scale-factor error and the input axis' misalignments beside the drift coefficients.
  Scenario s = default_scenario();
  s.gyro_rate = {150.0, -25.0, 40.0};
  s.test.counter_rate_offsets_rad_s = {0.0, 0.25, -0.25};
  s.test.revolutions = 8;
  s.test.sample_rate_hz = 50;
  s.test.settle_s = 1;
  s.uncertainty.counter_perpendicularity_x_rad = 0.1 * kArcsecToRad;
  write("rp.toml", scenario_to_toml(s));
  const std::string config = " --config " + path("rp.toml").string();
  const char* const rate_errors[] = {"scale_factor_error_ppm", "input_axis_misalignment_O_arcsec",
                                     "input_axis_misalignment_S_arcsec"};

  const Outcome sens = run("sensitivity --gyro-model drift+rate --json -" + config);
  ASSERT_EQ(sens.status, 0) << sens.err;
  const nlohmann::json js = nlohmann::json::parse(sens.out);
  EXPECT_EQ(js["gyro_model"], "drift+rate");
  EXPECT_EQ(js["units"]["scale_factor_error_ppm"], "ppm");
  for (const char* name : rate_errors) {
    // Each rate error has a shift per row and compensation, or is named unidentifiable with its reason.
    const bool named = js["not_identifiable"].contains(name);
    EXPECT_EQ(js["rows"][0]["least_squares"]["full"].contains(name), !named) << name;
    EXPECT_EQ(js["least_squares_noise_std"].contains(name), !named) << name;
  }
  EXPECT_TRUE(js["rows"][0]["least_squares"]["none"].contains("scale_factor_error_ppm"));
  EXPECT_TRUE(js["rows"][0]["least_squares"]["full"].contains("input_axis_misalignment_S_arcsec"));

  const Outcome mc = run("montecarlo --trials 200 --gyro-model drift+rate --json -" + config);
  ASSERT_EQ(mc.status, 0) << mc.err;
  const nlohmann::json jm = nlohmann::json::parse(mc.out);
  EXPECT_EQ(jm["gyro_model"], "drift+rate");
  for (const char* name : rate_errors) {
    const bool named = jm["not_identifiable"].contains(name);
    EXPECT_EQ(jm["coefficients"].contains(name), !named) << name;
    EXPECT_EQ(jm["budget"].contains(name), !named) << name;
  }
  const nlohmann::json& e = jm["coefficients"]["scale_factor_error_ppm"];
  EXPECT_EQ(e["unit"], "ppm");
  EXPECT_EQ(e["truth"], 150.0);
  for (const char* key : {"mean", "std", "predicted_std", "stated_std", "z_std", "histogram"})
    EXPECT_TRUE(e.contains(key)) << key;
  EXPECT_TRUE(jm["budget"]["scale_factor_error_ppm"].contains("counter_perpendicularity_x"));

  // The text output names them too.
  const Outcome text = run("montecarlo --trials 200 --gyro-model drift+rate" + config);
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("input_axis_misalignment_S_arcsec"), std::string::npos) << text.out;
  const Outcome sens_text = run("sensitivity --gyro-model drift+rate" + config);
  ASSERT_EQ(sens_text.status, 0) << sens_text.err;
  EXPECT_NE(sens_text.out.find("scale_factor_error_ppm (ppm"), std::string::npos) << sens_text.out;

  // [calibration] gyro_model is the default; the command line wins.
  s.gyro_model = GyroModel::kDriftRate;
  write("rp_rate.toml", scenario_to_toml(s));
  ASSERT_NE(slurp(path("rp_rate.toml")).find("gyro_model = \"drift+rate\""), std::string::npos);
  const std::string rate_config = " --config " + path("rp_rate.toml").string();
  const Outcome by_config = run("montecarlo --trials 200 --json -" + rate_config);
  ASSERT_EQ(by_config.status, 0) << by_config.err;
  EXPECT_TRUE(nlohmann::json::parse(by_config.out)["coefficients"].contains("scale_factor_error_ppm"));
  const Outcome overridden = run("sensitivity --gyro-model drift --json -" + rate_config);
  ASSERT_EQ(overridden.status, 0) << overridden.err;
  const nlohmann::json jo = nlohmann::json::parse(overridden.out);
  EXPECT_EQ(jo["gyro_model"], "drift");
  EXPECT_FALSE(jo["rows"][0]["least_squares"]["full"].contains("scale_factor_error_ppm"));

  // A bad value is refused naming the option, and nothing is written.
  for (const std::string sub : {"sensitivity", "montecarlo --trials 100"}) {
    const Outcome bad = run(sub + " --gyro-model foo --json " + path("out.json").string() + config);
    EXPECT_NE(bad.status, 0) << sub;
    EXPECT_NE(bad.err.find("--gyro-model"), std::string::npos) << sub << ": " << bad.err;
    EXPECT_NE(bad.err.find("{drift,drift+rate}"), std::string::npos) << sub << ": " << bad.err;
    EXPECT_FALSE(fs::exists(path("out.json"))) << sub;
  }
  // The closed forms identify the drift coefficients only: montecarlo says so.
  const Outcome closed = run("montecarlo --trials 100 --method closed-form --gyro-model drift+rate" + config);
  EXPECT_NE(closed.status, 0);
  EXPECT_NE(closed.err.find("closed forms identify the ten drift coefficients only"), std::string::npos)
      << closed.err;
}

// ---- Issue 20: files and messages a user can trust -----------------------------------------------------

// Item 1: --json follows the rule of --html and --out: an existing file is replaced only with --force, or
// when it is an earlier result of gyrocal (a JSON object with gyrocal's marker).
TEST_F(Cli, JsonReplacesOnlyAnEarlierResultOfGyrocalWithoutForce) {
  write("c.toml", short_test_toml());
  const std::string cfg = " --config " + path("c.toml").string();
  ASSERT_EQ(run("simulate --out " + path("r.csv").string() + cfg).status, 0);
  const std::string record = slurp(path("r.csv")), toml = slurp(path("c.toml"));
  const std::vector<std::pair<std::string, std::string>> commands = {
      {"calibrate " + path("r.csv").string() + cfg, "calibration"},
      {"plan" + cfg, "plan"},
      {"inputs --beta-deg 90 --time-s 1" + cfg, "inputs"},
      {"sensitivity" + cfg, "sensitivity"},
      {"montecarlo --trials 100" + cfg, "montecarlo"},
  };
  // A copy of the rig record, another configuration, and a JSON file that gyrocal did not write.
  const std::vector<std::pair<std::string, std::string>> precious = {
      {"rigcopy.txt", record}, {"other.toml", toml}, {"notes.json", "{\"mine\": [1, 2]}\n"}};
  for (const auto& [command, kind] : commands) {
    for (const auto& [name, text] : precious) {
      write(name, text);
      const Outcome refused = run(command + " --json " + path(name).string());
      EXPECT_EQ(refused.status, 1) << command << " --json " << name;
      EXPECT_NE(refused.err.find(path(name).string()), std::string::npos) << refused.err;
      EXPECT_NE(refused.err.find("not an earlier gyrocal result"), std::string::npos) << refused.err;
      EXPECT_NE(refused.err.find("--force"), std::string::npos) << refused.err;
      EXPECT_EQ(slurp(path(name)), text) << command << " --json " << name;
    }
    // A new file gets gyrocal's marker; an earlier result is replaced without --force.
    fs::remove(path("out.json"));
    const Outcome first = run(command + " --json " + path("out.json").string());
    ASSERT_EQ(first.status, 0) << command << ": " << first.err;
    const nlohmann::json j = nlohmann::json::parse(slurp(path("out.json")));
    EXPECT_EQ(j["gyrocal"]["result"], kind) << command;
    EXPECT_TRUE(j["gyrocal"]["version"].is_string()) << command;
    const Outcome again = run(command + " --json " + path("out.json").string());
    EXPECT_EQ(again.status, 0) << command << ": " << again.err;
    // Any file with --force.
    const Outcome forced = run(command + " --force --json " + path("notes.json").string());
    EXPECT_EQ(forced.status, 0) << command << ": " << forced.err;
    EXPECT_EQ(nlohmann::json::parse(slurp(path("notes.json")))["gyrocal"]["result"], kind) << command;
  }
  // The result of one command is an earlier result for another (results are re-creatable).
  EXPECT_EQ(run("plan" + cfg + " --json " + path("out.json").string()).status, 0);
  // The calibration names where it came from (item 8): the record, the configuration and the plan.
  ASSERT_EQ(run(commands[0].first + " --json " + path("out.json").string()).status, 0);
  const nlohmann::json j = nlohmann::json::parse(slurp(path("out.json")));
  EXPECT_EQ(j["record"], path("r.csv").string());
  EXPECT_EQ(j["config"], path("c.toml").string());
  EXPECT_EQ(j["plan"]["revolutions"], 12);
  EXPECT_TRUE(others({"c.toml", "r.csv", "out.json", "rigcopy.txt", "other.toml", "notes.json"}).empty());
}

// Item 10: `inputs` prints no negative zero.
TEST_F(Cli, InputsPrintsNoNegativeZero) {
  for (const std::string instant : {"--time-s 0", "--gamma-deg 0", "--gamma-deg 360"}) {
    const Outcome o = run("inputs --beta-deg 0 " + instant);
    ASSERT_EQ(o.status, 0) << o.err;
    EXPECT_EQ(o.out.find(" -0 "), std::string::npos) << instant << "\n" << o.out;
    EXPECT_NE(o.out.find("gamma"), std::string::npos);
  }
}

// Item 10: the sensitivity table fits a terminal: full names, values apart, every harmonic row with its
// phase.
TEST_F(Cli, SensitivityTableFitsATerminalAndNamesEveryRow) {
  write("c.toml", short_test_toml());
  const Outcome o = run("sensitivity --config " + path("c.toml").string());
  ASSERT_EQ(o.status, 0) << o.err;
  std::istringstream lines(o.out);
  std::string line;
  std::map<std::string, int> wobble_rows;
  std::size_t widest = 0;
  bool in_first_block = false;
  while (std::getline(lines, line)) {
    widest = std::max(widest, line.size());
    if (line.rfind("closed forms, compensation none", 0) == 0) in_first_block = true;
    if (line.rfind("closed forms, compensation seed", 0) == 0) in_first_block = false;
    // Rows of one harmonic differ by their phase.
    if (in_first_block && line.rfind("counter_wobble_x h2", 0) == 0)
      ++wobble_rows[line.substr(0, line.find("  "))];
  }
  EXPECT_LE(widest, 118u) << o.out;
  EXPECT_NE(o.out.find("dF+(1+Ar^2)dSS"), std::string::npos) << o.out;
  ASSERT_GE(wobble_rows.size(), 2u) << o.out;
  for (const auto& [label, n] : wobble_rows) EXPECT_EQ(n, 1) << label;
  // Numbers never run together: every shift is "name value", separated by ", ".
  const std::regex glued("[0-9]-[0-9]");
  EXPECT_FALSE(std::regex_search(o.out, glued)) << o.out;
}

// Item 10: --compensation seed and the seed paper's study are explained, and told apart from --seed.
TEST_F(Cli, HelpExplainsTheSeedCompensationAndTheSeedOption) {
  for (const std::string sub : {"calibrate", "plan", "montecarlo"}) {
    const Outcome h = run(sub + " --help");
    EXPECT_EQ(h.status, 0) << sub;
    EXPECT_NE(h.out.find("seed paper"), std::string::npos) << sub << h.out;
    EXPECT_NE(h.out.find("nothing to do with --seed"), std::string::npos) << sub << h.out;
  }
  const Outcome top = run("--help");
  EXPECT_NE(top.out.find("seed paper's error study"), std::string::npos) << top.out;
  const Outcome mc = run("montecarlo --help");
  EXPECT_NE(mc.out.find("not --compensation seed"), std::string::npos) << mc.out;
}

// Item 10: long work says how far it is when standard error is not a terminal (a log): a line per step.
TEST_F(Cli, ProgressIsALinePerStepWhenStandardErrorIsNotATerminal) {
  write("c.toml", short_test_toml());
  ::setenv("GYROCAL_PROGRESS_AFTER_S", "0", 1);
  const Outcome sens = run("sensitivity --config " + path("c.toml").string());
  const Outcome mc = run("montecarlo --trials 20000 --config " + path("c.toml").string());
  ::unsetenv("GYROCAL_PROGRESS_AFTER_S");
  for (const auto& [o, label] : {std::pair{&sens, "sensitivity"}, std::pair{&mc, "Monte Carlo"}}) {
    ASSERT_EQ(o->status, 0) << o->err;
    EXPECT_NE(o->err.find(std::string(label) + ": 100 % after"), std::string::npos) << o->err;
    EXPECT_EQ(o->err.find('\r'), std::string::npos) << "no bar redrawn in a log";
    EXPECT_GE(std::count(o->err.begin(), o->err.end(), '\n'), 2) << o->err;
  }
}

}  // namespace
}  // namespace gyrocal
