#pragma once
// Shared pieces of the command line: reading the configuration, writing outputs. No physics here.
#include <chrono>
#include <memory>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/atomic_file.hpp"
#include "gyrocal/identify/unknowns.hpp"
#include "gyrocal/reduce/dwell_accumulator.hpp"

namespace gyrocal::cli {

/// The built-in default scenario, or the configuration file at `path` when it is not empty.
Scenario load_configuration(const std::string& path);

/// The check that plan, simulate and calibrate share (reduce/feasibility.hpp), its refusal naming the
/// configuration file (or the built-in scenario). options: the reduction that will run (scenario.reduce,
/// with the command line's overrides).
void check_feasible(const Scenario& scenario, const std::string& config_path, const ReduceOptions& options);

/// An output: standard output for "-", else an AtomicOutputFile (a regular file through a temporary and a
/// rename; a device or FIFO written straight through; anything else refused). An existing regular file is
/// replaced only when `overwrite`.
std::unique_ptr<AtomicOutputFile> open_output(const std::string& path, bool overwrite);

/// Writes `content` to `path` through open_output and commits it.
void write_output(const std::string& path, std::string_view content, bool overwrite);

/// Refuse an output path that names one of the inputs (no input is ever overwritten).
void refuse_to_overwrite_input(const std::string& output, const std::string& input);

/// True when `path` is an earlier gyrocal report (it starts with kReportMarker, report/html_report.hpp),
/// which `report` and `noise --html` replace without --force: a report is derived from its input and cheap to
/// write again (docs/report.md).
bool is_earlier_report(const std::string& path);

/// A progress bar on standard error ("label [####    ]  42%"), redrawn when the whole percentage changes.
/// Commands install it only when standard error is a terminal; it draws nothing during the first second, so
/// that work shorter than a second shows no bar.
class ProgressBar {
 public:
  explicit ProgressBar(std::string label)
      : label_(std::move(label)), start_(std::chrono::steady_clock::now()) {}
  void operator()(double fraction);

 private:
  std::string label_;
  std::chrono::steady_clock::time_point start_;
  int percent_ = -1;
};

/// --gyro-model drift|drift+rate (docs/physics.md section 15) on `sub`, into `value` (empty when not given).
void add_gyro_model_option(CLI::App* sub, std::string& value);

/// The gyro model a command identifies: `option` (--gyro-model) when given, else [calibration] gyro_model.
GyroModel chosen_gyro_model(const std::string& option, const Scenario& scenario);

/// A check for a numeric option: refuses NaN and infinities ("--beta-deg nan"), which CLI11 parses.
extern const CLI::Validator kFinite;

/// Each subcommand registers itself on the application.
void register_init(CLI::App& app);
void register_inputs(CLI::App& app);
void register_demo(CLI::App& app);
void register_simulate(CLI::App& app);
void register_calibrate(CLI::App& app);
void register_plan(CLI::App& app);
void register_sensitivity(CLI::App& app);
void register_montecarlo(CLI::App& app);
void register_report(CLI::App& app);
void register_noise(CLI::App& app);

}  // namespace gyrocal::cli
