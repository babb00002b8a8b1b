// The command line's outputs and options (issue 29): text on a standard output that cannot be written fails
// the command (D5); demo --out follows the rule of every output (D6); --seed and the integer and number
// options are refused as given with their range (D11, D15); every output path is checked before the work
// (D12); inputs refuses an instant beyond any test (D17).
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;

using Outcome = test::CliOutcome;
using test::slurp;

constexpr const char* kNoSpace = "Cannot write standard output: No space left on device";

class Outputs : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::fresh_test_folder("gyrocal-outputs"); }
  void TearDown() override {
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add);
    fs::remove_all(dir_);
  }

  Outcome run(const std::string& args) const { return test::run_cli(args, dir_); }
  fs::path path(const std::string& name) const { return dir_ / name; }
  std::string p(const std::string& name) const { return path(name).string(); }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name), std::ios::binary) << text;
  }

  /// Runs `prefix gyrocal ARGS >REDIRECT` in the folder through the shell (prefix: shell commands before,
  /// e.g. `ulimit`); standard error is captured.
  Outcome run_to(const std::string& args, const std::string& redirect, const std::string& prefix = "") const {
    const fs::path err = dir_ / "stderr.txt";
    const std::string cmd = "cd " + dir_.string() + " && " + prefix + std::string(GYROCAL_CLI) + " " + args +
                            " " + redirect + " 2>" + err.string() + " </dev/null";
    const int raw = std::system(cmd.c_str());
    Outcome o;
    o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    o.err = slurp(err);
    fs::remove(err);
    return o;
  }

  /// A short gyro test (4 positions x 10 revolutions) and its record: s.toml, rec.csv.
  void make_record() const {
    write("s.toml", "[test]\nrevolutions = 10\n");
    const Outcome o = run("simulate --config " + p("s.toml") + " --out " + p("rec.csv"));
    ASSERT_EQ(o.status, 0) << o.err;
  }

  /// A static record of 600 s at 100 Hz: static.toml, static.csv.
  void make_static_record() const {
    write("static.toml",
          "[gyro.noise]\nangle_random_walk_deg_rt_h = 0.002\n[test]\nsample_rate_hz = 100.0\nrates_rad_s = "
          "[0.0]\nbeta_deg = [0.0]\ngamma_deg = [0.0]\nsettle_s = 0.0\nstatic_hold_s = 600.0\n");
    const Outcome o = run("simulate --config " + p("static.toml") + " --out " + p("static.csv"));
    ASSERT_EQ(o.status, 0) << o.err;
  }

  /// Files in the folder besides the given ones (staging folders, temporaries, outputs left behind).
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

// ---- D5: text to standard output ----------------------------------------------------------------------

TEST_F(Outputs, TextToAFullStandardOutputFailsEveryCommand) {
  make_record();
  make_static_record();
  for (const char* args : {"plan", "inputs --beta-deg 0 --time-s 1", "montecarlo --trials 100", "sensitivity",
                           "--help", "--version", "plan --help", "calibrate rec.csv --config s.toml",
                           "noise static.csv", "noise static.csv --toml", "plan --json -", "init -"}) {
    const Outcome o = run_to(args, ">/dev/full");
    EXPECT_EQ(o.status, 1) << args << ": " << o.err;
    EXPECT_NE(o.err.find(kNoSpace), std::string::npos) << args << ": " << o.err;
    EXPECT_EQ(o.err.find("internal error"), std::string::npos) << args << ": " << o.err;
  }
}

TEST_F(Outputs, AFailedAppendToStandardOutputLeavesTheFileAsItWas) {
  make_static_record();
  // A file of 1000 bytes that may grow to 1024 (ulimit -f counts 512-byte blocks in sh): the section cannot
  // be appended whole. SIGXFSZ ignored: the write fails with EFBIG, as it fails with ENOSPC on a full disk.
  const std::string before = std::string(999, '#') + "\n";
  write("cfg.toml", before);
  const Outcome o = run_to("noise static.csv --toml", ">>cfg.toml", "trap '' XFSZ; ulimit -f 2; ");
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_NE(o.err.find("Cannot write standard output: File too large"), std::string::npos) << o.err;
  EXPECT_EQ(slurp(path("cfg.toml")), before);
  // With room, the section is appended whole.
  const Outcome ok = run_to("noise static.csv --toml", ">>cfg.toml");
  ASSERT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(slurp(path("cfg.toml")).find("[gyro.noise]"), std::string::npos);
}

// ---- D6: demo --out -----------------------------------------------------------------------------------

// A demo whose standard output is closed early (`gyrocal demo | head -c1`) is ended by SIGPIPE while its
// files are staged: like SIGINT, SIGTERM and SIGHUP, the signal removes the staging folder (it was left, 7
// MB).
TEST_F(Outputs, ADemoEndedByABrokenPipeLeavesNoStagingFolder) {
  run_to("demo --out " + p("dp"), "| head -c1 >/dev/null");
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().filename().string().find(".dp.tmp"), std::string::npos)
        << "left behind: " << e.path().filename();
}

TEST_F(Outputs, DemoReplacesOnlyAnEarlierDemosFilesWithoutForce) {
  fs::create_directory(path("rig"));
  write("rig/record.csv", "rig data\n");
  write("rig/result.json", "{\"mine\": 1}\n");
  const Outcome refused = run("demo --out " + p("rig"));
  EXPECT_EQ(refused.status, 1) << refused.err;
  EXPECT_NE(refused.err.find("record.csv"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("--force"), std::string::npos) << refused.err;
  EXPECT_TRUE(refused.out.empty()) << "refused before any work: " << refused.out;
  EXPECT_EQ(slurp(path("rig/record.csv")), "rig data\n");
  EXPECT_EQ(slurp(path("rig/result.json")), "{\"mine\": 1}\n");
  std::vector<std::string> in_rig;
  for (const auto& e : fs::directory_iterator(path("rig"))) in_rig.push_back(e.path().filename().string());
  EXPECT_EQ(in_rig.size(), 2u) << "a staging folder left behind";

  // A gyrocal record in place, a foreign result beside it: the result stops the demo.
  make_record();
  fs::copy_file(path("rec.csv"), path("rig/record.csv"), fs::copy_options::overwrite_existing);
  const Outcome result_refused = run("demo --out " + p("rig"));
  EXPECT_EQ(result_refused.status, 1) << result_refused.err;
  EXPECT_NE(result_refused.err.find("result.json"), std::string::npos) << result_refused.err;
  EXPECT_EQ(slurp(path("rig/result.json")), "{\"mine\": 1}\n");

  // --force replaces them; an earlier demo's files are then replaced without it (scripts/demo, .ci/run).
  ASSERT_EQ(run("demo --force --out " + p("rig")).status, 0);
  EXPECT_EQ(slurp(path("rig/record.csv")).rfind("# gyrocal-record 1", 0), 0u);
  const Outcome again = run("demo --out " + p("rig"));
  EXPECT_EQ(again.status, 0) << again.err;
  EXPECT_NE(again.out.find("wrote"), std::string::npos) << again.out;

  // A foreign report is refused too.
  write("rig/report.html", "<html>mine</html>\n");
  const Outcome report_refused = run("demo --out " + p("rig"));
  EXPECT_EQ(report_refused.status, 1) << report_refused.err;
  EXPECT_NE(report_refused.err.find("report.html"), std::string::npos) << report_refused.err;
  EXPECT_EQ(slurp(path("rig/report.html")), "<html>mine</html>\n");
}

// ---- D11: --seed ----------------------------------------------------------------------------------------

TEST_F(Outputs, SeedOutsideZeroToTwoToThe64IsRefusedAsGiven) {
  for (const std::string& command : {"simulate --out " + p("r.csv"), std::string("montecarlo --trials 10")}) {
    for (const std::string seed :
         {"-1", "-5", "18446744073709551616", "99999999999999999999999", "1.5", "''"}) {
      const Outcome o = run(command + " --seed " + seed);
      EXPECT_NE(o.status, 0) << command << " --seed " << seed;
      EXPECT_NE(o.err.find("--seed"), std::string::npos) << o.err;
      EXPECT_NE(o.err.find("from 0 to 18446744073709551615"), std::string::npos) << o.err;
      EXPECT_NE(o.err.find("not " + seed), std::string::npos) << o.err;
    }
  }
  EXPECT_FALSE(fs::exists(path("r.csv")));
  // The whole range is taken as written (a leading zero is not octal).
  write("s.toml", "[test]\nrevolutions = 10\n");
  for (const std::string seed : {"18446744073709551615", "010"}) {
    const Outcome o = run("simulate --config " + p("s.toml") + " --out - --seed " + seed);
    ASSERT_EQ(o.status, 0) << o.err;
    EXPECT_NE(o.out.find("# seed = " + (seed == "010" ? std::string("10") : seed) + "\n"), std::string::npos);
  }
}

// ---- D12: outputs checked before the work ----------------------------------------------------------

TEST_F(Outputs, EveryOutputPathIsCheckedBeforeTheWork) {
  write("foreign.txt", "x\n");
  fs::create_directory(path("folder"));
  // The work would show progress from its start (GYROCAL_PROGRESS_AFTER_S=0): none shows.
  const std::string progress = "GYROCAL_PROGRESS_AFTER_S=0 ";
  for (const std::string& json : {p("foreign.txt"), p("folder"), p("missing/x.json")}) {
    const Outcome mc = run_to("montecarlo --trials 100000 --json " + json, ">/dev/null", progress);
    EXPECT_EQ(mc.status, 1) << mc.err;
    EXPECT_NE(mc.err.find(json), std::string::npos) << mc.err;
    EXPECT_EQ(mc.err.find("Monte Carlo:"), std::string::npos) << mc.err;
    const Outcome sens = run_to("sensitivity --json " + json, ">/dev/null", progress);
    EXPECT_EQ(sens.status, 1) << sens.err;
    EXPECT_NE(sens.err.find(json), std::string::npos) << sens.err;
    EXPECT_EQ(sens.err.find("sensitivity:"), std::string::npos) << sens.err;
  }
  EXPECT_NE(run("montecarlo --trials 10 --json " + p("foreign.txt")).err.find("--force"), std::string::npos);
  // The output's refusal comes before the inputs are read: here, before a record or a result that does
  // not exist is found missing.
  const std::string missing = p("nothing-here.csv");
  for (const std::string& args :
       {"calibrate " + missing + " --json " + p("foreign.txt"),
        "noise " + missing + " --json " + p("foreign.txt"),
        "noise " + missing + " --html " + p("missing/r.html"),
        "report " + missing + " --html " + p("foreign.txt"),
        "plan --config " + missing + " --json " + p("folder"),
        "inputs --config " + missing + " --beta-deg 0 --time-s 1 --json " + p("foreign.txt"),
        "simulate --config " + missing + " --out " + p("foreign.txt")}) {
    const Outcome o = run(args);
    EXPECT_EQ(o.status, 1) << args << ": " << o.err;
    EXPECT_EQ(o.err.find("nothing-here"), std::string::npos) << args << ": " << o.err;
  }
  EXPECT_EQ(slurp(path("foreign.txt")), "x\n");
  EXPECT_TRUE(others({"foreign.txt", "folder"}).empty());
  // --force lets the check pass: the refusal is then the missing input's.
  EXPECT_NE(run("calibrate " + missing + " --json " + p("foreign.txt") + " --force").err.find("nothing-here"),
            std::string::npos);
}

// ---- D15: option refusals ------------------------------------------------------------------------------

TEST_F(Outputs, OptionRefusalsNameTheOptionTheValueAsGivenAndTheRange) {
  struct Case {
    std::string args, option, range, value;
  };
  const std::vector<Case> cases = {
      {"sensitivity --threshold 0", "--threshold", "a finite number > 0", "not 0"},
      {"sensitivity --threshold -1e-320", "--threshold", "a finite number > 0", "not -1e-320"},
      {"sensitivity --threshold nan", "--threshold", "a finite number > 0", "not nan"},
      {"sensitivity --threads -1", "--threads", "from 0 to 1024", "not -1"},
      {"montecarlo --trials 10 --threads -1", "--threads", "from 0 to 1024", "not -1"},
      {"montecarlo --trials 10 --threads 4096", "--threads", "from 0 to 1024", "not 4096"},
      {"montecarlo --trials ''", "--trials", "from 2 to 1000000000", "not ''"},
      {"montecarlo --trials 99999999999999999999", "--trials", "from 2 to 1000000000",
       "not 99999999999999999999"},
      {"montecarlo --trials 2.5", "--trials", "from 2 to 1000000000", "not 2.5"},
      {"inputs --beta-deg 0 --gamma-deg 0 --revolution -1", "--revolution", "from 0 to 2147483647", "not -1"},
      {"inputs --beta-deg 0 --gamma-deg 0 --revolution ''", "--revolution", "from 0 to 2147483647", "not ''"},
  };
  for (const Case& c : cases) {
    const Outcome o = run(c.args);
    EXPECT_NE(o.status, 0) << c.args;
    EXPECT_NE(o.err.find(c.option), std::string::npos) << c.args << ": " << o.err;
    EXPECT_NE(o.err.find(c.range), std::string::npos) << c.args << ": " << o.err;
    EXPECT_NE(o.err.find(c.value), std::string::npos) << c.args << ": " << o.err;
    EXPECT_EQ(o.err.find("1797693"), std::string::npos) << c.args << ": " << o.err;
    EXPECT_EQ(o.err.find("9223372036854775807"), std::string::npos) << c.args << ": " << o.err;
    EXPECT_EQ(o.err.find("0.000000"), std::string::npos) << c.args << ": " << o.err;
  }
  // An exact integer in exponent form is a number of trials.
  EXPECT_EQ(run("montecarlo --trials 1e2").status, 0);
}

// ---- D17: inputs beyond any test -----------------------------------------------------------------------

TEST_F(Outputs, InputsRefusesAnInstantBeyondTheLongestTest) {
  for (const std::string args :
       {"--time-s 1e308", "--time-s -1e308", "--time-s 5.1e7", "--gamma-deg 10 --revolution 2000000000"}) {
    const Outcome o = run("inputs --beta-deg 0 " + args + " --json " + p("in.json"));
    EXPECT_EQ(o.status, 1) << args << ": " << o.err;
    EXPECT_NE(o.err.find(args.substr(0, args.find(' '))), std::string::npos) << o.err;
    EXPECT_NE(o.err.find("5e+07 s"), std::string::npos) << o.err;  // 1e10 samples at 200 Hz
    EXPECT_TRUE(o.out.empty()) << o.out;
    EXPECT_FALSE(fs::exists(path("in.json")));
  }
  // The longest test's last instant is finite everywhere.
  const Outcome o = run("inputs --beta-deg 0 --time-s 5e7 --json -");
  ASSERT_EQ(o.status, 0) << o.err;
  const nlohmann::json j = nlohmann::json::parse(o.out);
  for (const char* key : {"omega_rad_s", "specific_force_g"})
    for (const auto& v : j[key]) EXPECT_TRUE(v.is_number()) << key << " " << v;
  const Outcome table = run("inputs --beta-deg 0 --time-s 5e7");
  EXPECT_EQ(table.out.find("nan"), std::string::npos) << table.out;
  EXPECT_EQ(table.out.find("inf"), std::string::npos) << table.out;
}

}  // namespace
}  // namespace gyrocal
