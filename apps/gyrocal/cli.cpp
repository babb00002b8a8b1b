#include "cli.hpp"

#include <unistd.h>

#include <cctype>
#include <charconv>
#include <climits>
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

namespace {

/// A value as the user gave it, for a refusal: '' for an empty one.
std::string as_given(const std::string& text) {
  return text.empty() ? std::string("''") : text;
}

bool all_digits(std::string_view text, std::size_t from) {
  if (text.size() <= from) return false;
  for (std::size_t i = from; i < text.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(text[i]))) return false;
  return true;
}

}  // namespace

const CLI::Validator kPositiveFinite(
    [](std::string& text) -> std::string {
      double value = 0.0;
      if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value) || !(value > 0.0))
        return "must be a finite number > 0, not " + as_given(text);
      return {};
    },
    "NUMBER > 0", "POSITIVE_FINITE");

const CLI::Validator kSeed(
    [](std::string& text) -> std::string {
      std::uint64_t value = 0;
      const char* end = text.data() + text.size();
      if (!all_digits(text, 0) || std::from_chars(text.data(), end, value).ec != std::errc())
        return fmt::format("must be an integer from 0 to {}, not {}", UINT64_MAX, as_given(text));
      text = std::to_string(value);  // in decimal for CLI11, which reads a leading 0 as octal
      return {};
    },
    "INTEGER 0..2^64-1", "SEED");

CLI::Validator integer_between(long long least, long long most, bool check_range) {
  return CLI::Validator(
      [least, most, check_range](std::string& text) -> std::string {
        const std::string refusal =
            fmt::format("must be an integer from {} to {}, not {}", least, most, as_given(text));
        long long value = 0;
        const char* end = text.data() + text.size();
        const std::size_t digits_from = !text.empty() && text[0] == '-' ? 1 : 0;
        if (all_digits(text, digits_from)) {
          if (std::from_chars(text.data(), end, value).ec != std::errc()) return refusal;
        } else {
          // An exact integer in exponent form ("1e6"); the range check below bounds it.
          if (text.find_first_not_of("0123456789+-.eE") != std::string::npos) return refusal;
          char* parsed = nullptr;
          const double number = text.empty() ? NAN : std::strtod(text.c_str(), &parsed);
          if (parsed != end || !std::isfinite(number) || number != std::floor(number) ||
              std::fabs(number) > 9e18)
            return refusal;
          value = static_cast<long long>(number);
        }
        if (check_range && (value < least || value > most)) return refusal;
        text = std::to_string(value);
        return {};
      },
      fmt::format("INTEGER {}..{}", least, most), "INTEGER_BETWEEN");
}

const char* const kCompensationHelp =
    "What is subtracted from each measurement before the fit: none; seed, the correction of the seed paper "
    "this method comes from (Wang & Meng 2017, docs/physics.md section 8): the counter platform's "
    "perpendicularity, wobble tilt and rate mismatch only (nothing to do with --seed, the random seed of "
    "simulate and montecarlo); or full (default), every configured machine error. none and seed are a "
    "gyro's; "
    "an accelerometer is calibrated with full";

std::string size_text(std::uintmax_t bytes) {
  if (bytes >= 1000000000000) return fmt::format("{:.1f} TB", static_cast<double>(bytes) / 1e12);
  if (bytes >= 1000000000) return fmt::format("{:.1f} GB", static_cast<double>(bytes) / 1e9);
  if (bytes >= 1000000) return fmt::format("{:.1f} MB", static_cast<double>(bytes) / 1e6);
  if (bytes >= 1000) return fmt::format("{:.1f} kB", static_cast<double>(bytes) / 1e3);
  return fmt::format("{} bytes", bytes);
}

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
    case OutputKind::kDemoRecord:
      return is_simulated_record(path);
    case OutputKind::kRecord:
    case OutputKind::kConfiguration:
      break;
  }
  return false;
}

}  // namespace

bool may_replace(const std::string& path, OutputKind kind, bool force, std::string_view option) {
  if (force || is_earlier_output(path, kind)) return true;
  std::error_code ec;
  if (kind == OutputKind::kRecord || kind == OutputKind::kConfiguration ||
      !std::filesystem::is_regular_file(path, ec))
    return false;
  const char* what = kind == OutputKind::kResult   ? "result"
                     : kind == OutputKind::kReport ? "report"
                                                   : "record";
  const char* earlier = kind == OutputKind::kResult ? "a JSON object with gyrocal's \"gyrocal\" marker"
                        : kind == OutputKind::kReport
                            ? "an HTML file that starts with gyrocal's report comment"
                            : "a record gyrocal simulated, whose metadata says '# generator = gyrocal "
                              "simulate'";
  throw Error(fmt::format(
      "refusing to replace '{}' ({}): it exists and is not an earlier gyrocal {} ({}); give --force to "
      "replace it.",
      path, option, what, earlier));
}

void check_output(const std::string& path, OutputKind kind, bool force, std::string_view option) {
  if (path.empty() || path == "-") return;
  AtomicOutputFile::check(path, may_replace(path, kind, force, option));
}

std::unique_ptr<AtomicOutputFile> open_output(const std::string& path, OutputKind kind, bool force,
                                              std::string_view option) {
  if (path == "-") return std::make_unique<AtomicOutputFile>(AtomicOutputFile::StandardOutput{});
  return std::make_unique<AtomicOutputFile>(path, may_replace(path, kind, force, option));
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

bool is_simulated_record(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  // The first line and the metadata lines after it, within the first 64 KiB (a file without line ends, or
  // a long preamble, is not read further).
  constexpr std::size_t kHeadBytes = std::size_t{64} << 10;
  std::ifstream in(path, std::ios::binary);
  std::string head(kHeadBytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::size_t from = 0;
  for (std::size_t line = 0;; ++line) {
    const std::size_t end = head.find('\n', from);
    if (end == std::string::npos) return false;
    const std::string_view text = std::string_view(head).substr(from, end - from);
    if (line == 0 && text != "# gyrocal-record 1") return false;
    if (line > 0 && (text.empty() || text[0] != '#')) return false;  // the header: no generator line
    if (text == "# generator = gyrocal simulate") return true;
    from = end + 1;
  }
}

bool is_earlier_result(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  // Read as `report` reads a result (read_result_file): bounded by limits::kResultBytes through
  // read_bounded, stopping at the first character when it cannot open a JSON object (a record or a
  // configuration is told apart without reading it), and held to a result's names and depth.
  try {
    return has_result_marker(read_result_file(path));
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
         "A gyro's model (an accelerometer has one, IEEE 1293's): drift (the ten drift coefficients) or "
         "drift+rate (also the scale-factor error and the input axis' misalignments, by least squares); "
         "default: [calibration] gyro_model, else drift")
      ->check(CLI::IsMember({"drift", "drift+rate"}));
}

GyroModel chosen_gyro_model(const std::string& option, const Scenario& scenario) {
  return option.empty() ? scenario.gyro_model : parse_gyro_model(option);
}

}  // namespace gyrocal::cli
