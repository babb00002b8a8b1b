#include "cli.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <fmt/format.h>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/atomic_file.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/reduce/feasibility.hpp"
#include "gyrocal/report/html_report.hpp"

namespace gyrocal::cli {

const CLI::Validator kFinite(
    [](std::string& text) -> std::string {
      double value = 0.0;
      if (!CLI::detail::lexical_cast(text, value)) return "'" + text + "' is not a number";
      if (!std::isfinite(value)) return "must be a finite number, not " + text;
      return {};
    },
    "FINITE", "FINITE");

Scenario load_configuration(const std::string& path) {
  return path.empty() ? default_scenario() : load_scenario(path);
}

void check_feasible(const Scenario& scenario, const std::string& config_path, const ReduceOptions& options) {
  try {
    check_test_feasible(scenario.test, options, scenario.centrifuge.rate_rad_s);
  } catch (const Error& e) {
    throw Error((config_path.empty() ? std::string("the built-in scenario") : config_path) + ": " + e.what());
  }
}

std::unique_ptr<AtomicOutputFile> open_output(const std::string& path, bool overwrite) {
  if (path == "-") return std::make_unique<AtomicOutputFile>(AtomicOutputFile::StandardOutput{});
  return std::make_unique<AtomicOutputFile>(path, overwrite);
}

void write_output(const std::string& path, std::string_view content, bool overwrite) {
  const std::unique_ptr<AtomicOutputFile> file = open_output(path, overwrite);
  file->write(content);
  file->commit();
}

void refuse_to_overwrite_input(const std::string& output, const std::string& input) {
  if (output.empty() || output == "-" || input.empty()) return;
  std::error_code ec;
  if (std::filesystem::equivalent(output, input, ec))
    throw Error("refusing to write " + output + ": it is the input " + input + ".");
}

bool is_earlier_report(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::string head(kReportMarker.size(), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  return in.gcount() == static_cast<std::streamsize>(head.size()) && head == kReportMarker;
}

void ProgressBar::operator()(double fraction) {
  const int percent = static_cast<int>(fraction * 100.0);
  if (percent == percent_) return;
  // Nothing during the first second (a bar never drawn is not completed either).
  if (percent_ < 0 && std::chrono::steady_clock::now() - start_ < std::chrono::seconds(1)) return;
  percent_ = percent;
  constexpr int kWidth = 40;
  const int filled = percent * kWidth / 100;
  fmt::print(stderr, "\r{} [{:#<{}}{:<{}}] {:3}%", label_, "", filled, "", kWidth - filled, percent);
  if (percent == 100) fmt::print(stderr, "\n");
  std::fflush(stderr);
}

void add_gyro_model_option(CLI::App* sub, std::string& value) {
  sub->add_option(
         "--gyro-model", value,
         "drift (the ten coefficients) or drift+rate (also the scale-factor error and the input axis' "
         "misalignments, by least squares); default: [calibration] gyro_model, else drift")
      ->check(CLI::IsMember({"drift", "drift+rate"}));
}

GyroModel chosen_gyro_model(const std::string& option, const Scenario& scenario) {
  return option.empty() ? scenario.gyro_model : parse_gyro_model(option);
}

}  // namespace gyrocal::cli
