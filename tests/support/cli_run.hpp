#pragma once
// Running the command line from a test: a fresh folder per test, the CLI with its output captured, the
// outcome. Header-only; the CLI's path comes from GYROCAL_CLI (tests/CMakeLists.txt).
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"

namespace gyrocal::test {

/// What a run of the CLI gave: its exit status (-1 if it did not exit normally), standard output and error.
struct CliOutcome {
  int status = -1;
  std::string out, err;
};

/// The whole content of a file ("" if it cannot be read).
inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A new, empty folder for the running test: <temp>/<prefix>-<test name>-<pid>.
inline std::filesystem::path fresh_test_folder(const std::string& prefix) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      (prefix + "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name() + "-" +
       std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Runs `gyrocal ARGS` through the shell (ARGS as written on a command line), standard input from
/// /dev/null, its outputs captured through files in `dir`, which are removed again.
inline CliOutcome run_cli(const std::string& args, const std::filesystem::path& dir) {
  const std::filesystem::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd =
      std::string(GYROCAL_CLI) + " " + args + " >" + out.string() + " 2>" + err.string() + " </dev/null";
  const int raw = std::system(cmd.c_str());
  CliOutcome o;
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  o.out = slurp(out);
  o.err = slurp(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return o;
}

/// The sentence parsing configuration text `toml` (as the file `name`) is refused with; "" if it parses.
inline std::string config_error(const std::string& toml, const std::string& name = "rig.toml") {
  try {
    parse_scenario(toml, name);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

/// `gyrocal calibrate DIR/RECORD --config DIR/rig.toml --json -EXTRA`, the configuration text `toml` written
/// to DIR/rig.toml first: the rig tests' round trip through the command line (the JSON on the outcome's out).
inline CliOutcome calibrate_in(const std::filesystem::path& dir, const std::string& record,
                               const std::string& toml, const std::string& extra = "") {
  {
    std::ofstream file(dir / "rig.toml");
    file << toml;
  }
  return run_cli("calibrate " + (dir / record).string() + " --config " + (dir / "rig.toml").string() +
                     " --json -" + extra,
                 dir);
}

/// A short test (12 revolutions per dwell at 100 Hz) so that a command-line round trip is quick.
inline std::string short_test_toml() {
  Scenario s = default_scenario();
  s.test.revolutions = 12;
  s.test.sample_rate_hz = 100;
  s.test.settle_s = 1;
  return scenario_to_toml(s);
}

}  // namespace gyrocal::test
