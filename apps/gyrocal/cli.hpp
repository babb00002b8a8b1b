#pragma once
// Shared pieces of the command line: reading the configuration, writing outputs. No physics here.
#include <memory>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/atomic_file.hpp"

namespace gyrocal::cli {

/// The built-in default scenario, or the configuration file at `path` when it is not empty.
Scenario load_configuration(const std::string& path);

/// An output: standard output for "-", else an AtomicOutputFile (a regular file through a temporary and a
/// rename; a device or FIFO written straight through; anything else refused). An existing regular file is
/// replaced only when `overwrite`.
std::unique_ptr<AtomicOutputFile> open_output(const std::string& path, bool overwrite);

/// Writes `content` to `path` through open_output and commits it.
void write_output(const std::string& path, std::string_view content, bool overwrite);

/// Refuse an output path that names one of the inputs (no input is ever overwritten).
void refuse_to_overwrite_input(const std::string& output, const std::string& input);

/// A progress bar on standard error ("label [####    ]  42%"), redrawn when the whole percentage changes.
/// Commands install it only when standard error is a terminal.
class ProgressBar {
 public:
  explicit ProgressBar(std::string label) : label_(std::move(label)) {}
  void operator()(double fraction);

 private:
  std::string label_;
  int percent_ = -1;
};

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

}  // namespace gyrocal::cli
