#include "cli.hpp"

#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>

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

const char* const kCompensationHelp =
    "What is subtracted from each measurement before the fit: none; seed, the correction of the seed paper "
    "this method comes from (Wang & Meng 2017, docs/physics.md section 8): the counter platform's "
    "perpendicularity, wobble tilt and rate mismatch only (nothing to do with --seed, the random seed of "
    "simulate and montecarlo); or full (default), every configured machine error";

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

namespace {

bool is_earlier_output(const std::string& path, OutputKind kind) {
  switch (kind) {
    case OutputKind::kResult:
      return is_earlier_result(path);
    case OutputKind::kReport:
      return is_earlier_report(path);
    case OutputKind::kRecord:
    case OutputKind::kConfiguration:
      break;
  }
  return false;
}

}  // namespace

std::unique_ptr<AtomicOutputFile> open_output(const std::string& path, OutputKind kind, bool force,
                                              std::string_view option) {
  if (path == "-") return std::make_unique<AtomicOutputFile>(AtomicOutputFile::StandardOutput{});
  const bool replace = force || is_earlier_output(path, kind);
  std::error_code ec;
  if (!replace && (kind == OutputKind::kResult || kind == OutputKind::kReport) &&
      std::filesystem::is_regular_file(path, ec))
    throw Error(fmt::format(
        "refusing to replace '{}' ({}): it exists and is not an earlier gyrocal {} ({}); give --force to "
        "replace it.",
        path, option, kind == OutputKind::kResult ? "result" : "report",
        kind == OutputKind::kResult ? "a JSON object with gyrocal's \"gyrocal\" marker"
                                    : "an HTML file that starts with gyrocal's report comment"));
  return std::make_unique<AtomicOutputFile>(path, replace);
}

void write_output(const std::string& path, std::string_view content, OutputKind kind, bool force,
                  std::string_view option) {
  const std::unique_ptr<AtomicOutputFile> file = open_output(path, kind, force, option);
  file->write(content);
  file->commit();
}

void write_result(const std::string& path, nlohmann::ordered_json result, std::string_view kind, bool force) {
  mark_result(result, kind);
  write_output(path, result.dump(2) + "\n", OutputKind::kResult, force, "--json");
}

void add_force_flag(CLI::App* sub, bool& force) {
  sub->add_flag("--force", force,
                "Let --json (and --html) replace an existing file that is not an earlier output of gyrocal; "
                "without it only an earlier result (or report) of gyrocal is replaced");
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

bool is_earlier_result(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  // A result is a few MB at most; a bigger file is something else (a record), and is not read.
  constexpr std::uintmax_t kLargestResult = 256u << 20;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec || size > kLargestResult) return false;
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  // The first character that is not white space must open an object: a record or a configuration is
  // told apart without reading it.
  char c = 0;
  while (in.get(c) && std::isspace(static_cast<unsigned char>(c))) {
  }
  if (!in || c != '{') return false;
  std::string text(1, c);
  text.append(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  try {
    return has_result_marker(parse_result_json(text, path));
  } catch (const Error&) {
    return false;
  }
}

namespace {

/// How long work runs before progress shows: 1 s, or $GYROCAL_PROGRESS_AFTER_S (a number of seconds >= 0;
/// 0 shows progress from the start, e.g. in a log; anything else is ignored).
std::chrono::duration<double> progress_delay() {
  if (const char* text = std::getenv("GYROCAL_PROGRESS_AFTER_S"); text && *text) {
    char* end = nullptr;
    const double seconds = std::strtod(text, &end);
    if (end && *end == '\0' && std::isfinite(seconds) && seconds >= 0)
      return std::chrono::duration<double>(seconds);
  }
  return std::chrono::seconds(1);
}

}  // namespace

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)),
      start_(std::chrono::steady_clock::now()),
      delay_(progress_delay()),
      terminal_(::isatty(STDERR_FILENO) != 0) {}

void ProgressBar::operator()(double fraction) {
  const int percent = static_cast<int>(fraction * 100.0);
  // Not a terminal: a line per tenth; a terminal: the bar redrawn per percent.
  const int step = terminal_ ? percent : percent / 10 * 10;
  if (step == percent_) return;
  // Nothing during the first second (a bar never drawn is not completed either).
  const auto elapsed = std::chrono::steady_clock::now() - start_;
  if (percent_ < 0 && elapsed < delay_) return;
  percent_ = step;
  if (!terminal_) {
    fmt::print(stderr, "{}: {:3} % after {:.1f} s\n", label_, step,
               std::chrono::duration<double>(elapsed).count());
    std::fflush(stderr);
    return;
  }
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
