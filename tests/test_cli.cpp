// The command line as a user drives it: init, inputs, simulate, calibrate, plan; files, JSON and errors.
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
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
    const GyroInputs fd = test_support::finite_difference_inputs(
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

}  // namespace
}  // namespace gyrocal
