#pragma once
// Shared pieces of the command line: reading the configuration, writing outputs. No physics here.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/atomic_file.hpp"
#include "gyrocal/identify/unknowns.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/reduce/dwell_accumulator.hpp"

namespace gyrocal::cli {

/// A file's size as a user reads it: "16.7 MB", "512 bytes" (powers of 1000).
std::string size_text(std::uintmax_t bytes);

/// The built-in default scenario, or the configuration file at `path` when it is not empty.
Scenario load_configuration(const std::string& path);

/// The check that plan, simulate and calibrate share (reduce/feasibility.hpp), its refusal naming the
/// configuration file (or the built-in scenario). options: the reduction that will run (scenario.reduce,
/// with the command line's overrides).
void check_feasible(const Scenario& scenario, const std::string& config_path, const ReduceOptions& options);

/// What an output option writes; it decides when an existing file may be replaced (replacement_rule).
enum class OutputKind {
  kRecord,         ///< simulate --out: a record (possibly a rig's), never re-creatable by gyrocal
  kConfiguration,  ///< init FILE: a configuration the user may have edited
  kResult,         ///< --json FILE: a result (gyrocal's marker, report/html_report.hpp)
  kReport,         ///< --html FILE: a report (kReportMarker)
  kDemoRecord,     ///< demo --out DIR's record.csv: a record simulated by gyrocal (is_simulated_record)
};

/// The one rule for every output option (docs/interface.md, "Files"): "-" is standard output; a path that
/// does not exist is created; an existing regular file is replaced when `force` (--force), and without it
/// only when it is an earlier output of the same kind written by gyrocal (a result JSON with gyrocal's
/// marker for --json, a report for --html; a record or a configuration always needs --force). A device or
/// FIFO is written straight through (AtomicOutputFile). Refuses, naming `option` and the path, a file it
/// may not replace. Inputs are refused before, by refuse_to_overwrite_input.
std::unique_ptr<AtomicOutputFile> open_output(const std::string& path, OutputKind kind, bool force,
                                              std::string_view option);

/// open_output's rule applied to `path` before a command's work, creating nothing (AtomicOutputFile::check):
/// throws the same gyrocal::Error open_output would (a file it may not replace, a folder, a dangling link, a
/// folder that does not exist or cannot take a file). Nothing for an empty path (no output) or "-".
/// open_output checks again at the end: the file system may change meanwhile.
void check_output(const std::string& path, OutputKind kind, bool force, std::string_view option);

/// Whether open_output's rule lets an existing regular file at `path` be replaced: true with `force` or when
/// it is an earlier output of `kind`; false for a record or a configuration without `force` (the caller
/// refuses "exists; use --force"); for a result, a report or a demo's record that is not an earlier one,
/// throws gyrocal::Error naming `option`, the path, what an earlier output is and --force.
bool may_replace(const std::string& path, OutputKind kind, bool force, std::string_view option);

/// Writes `content` to `path` through open_output and commits it.
void write_output(const std::string& path, std::string_view content, OutputKind kind, bool force,
                  std::string_view option);

/// Writes `result` as the JSON of a `kind` result (kResultKinds: calibration, plan, sensitivity, montecarlo,
/// noise, inputs) to `path` (--json), with gyrocal's marker added (mark_result), by the rule of open_output.
void write_result(const std::string& path, nlohmann::ordered_json result, std::string_view kind, bool force);

/// --force for the commands whose outputs follow open_output's rule: replace any existing file.
void add_force_flag(CLI::App* sub, bool& force);

/// Refuse an output path that names one of the inputs (no input is ever overwritten).
void refuse_to_overwrite_input(const std::string& output, const std::string& input);

/// True when `path` is a record simulated by gyrocal: its first line is '# gyrocal-record 1' and a metadata
/// line before its header says '# generator = gyrocal simulate' (only the first 64 KiB are read).
bool is_simulated_record(const std::string& path);

/// Text for standard output: every command prints through this (docs/interface.md, "Text output"), so
/// that a write error (a full disk, /dev/full) fails the command, exit 1, with "Cannot write standard
/// output: <reason>." (write_standard_output, core/atomic_file.hpp).
template <typename... Args>
void print_out(fmt::format_string<Args...> format, Args&&... args) {
  write_standard_output(fmt::format(format, std::forward<Args>(args)...));
}

/// True when `path` is an earlier gyrocal report (it starts with kReportMarker, report/html_report.hpp).
bool is_earlier_report(const std::string& path);

/// True when `path` is a regular file that holds an earlier gyrocal result: a JSON object with gyrocal's
/// marker (has_result_marker, report/html_report.hpp).
bool is_earlier_result(const std::string& path);

/// Progress on standard error. On a terminal, a bar ("label [####    ]  42%") redrawn when the whole
/// percentage changes; otherwise (a file, a pipe, a log) one line per tenth ("label: 40 % after 3.2 s").
/// Both only from the first second on, so that work shorter than a second shows none
/// ($GYROCAL_PROGRESS_AFTER_S sets another delay, 0 = from the start; docs/interface.md).
class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  void operator()(double fraction);

 private:
  std::string label_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::duration<double> delay_;
  bool terminal_;
  int percent_ = -1;
};

/// --gyro-model drift|drift+rate (docs/physics.md section 15) on `sub`, into `value` (empty when not given).
void add_gyro_model_option(CLI::App* sub, std::string& value);

/// The gyro model a command identifies: `option` (--gyro-model) when given, else [calibration] gyro_model.
GyroModel chosen_gyro_model(const std::string& option, const Scenario& scenario);

/// --compensation's help: what "seed" means (the seed paper's correction, not the random --seed).
extern const char* const kCompensationHelp;

/// A check for a numeric option: refuses NaN and infinities ("--beta-deg nan"), which CLI11 parses.
extern const CLI::Validator kFinite;

/// A floating-point option that must be a finite number > 0 ("--threshold: must be a finite number > 0,
/// not 0").
extern const CLI::Validator kPositiveFinite;

/// --seed: a decimal integer from 0 to 2^64 - 1 = 18446744073709551615, refused as given otherwise (a sign,
/// an empty value, more than 2^64 - 1), as the Python module refuses it.
extern const CLI::Validator kSeed;

/// An integer option from `least` to `most`, in decimal (or an exact integer in exponent form, "1e6"):
/// anything else, an empty value included, is refused as given with the range ("--trials: must be an
/// integer from 2 to 1000000000, not ''"), never read as 0 or as a saturated value. Add it with transform()
/// (it rewrites the value in plain decimal).
/// With `check_range` false, only what is not an integer (or lies beyond a long long) is refused here, with
/// the same message; the command refuses the rest of the range itself, with its reason (montecarlo --trials).
CLI::Validator integer_between(long long least, long long most, bool check_range = true);

// ---- The calibration history (docs/history.md) ----

/// The history database a command uses: `option` (--db, --history) when given; else [history] database of
/// `scenario` (a relative path taken from the folder of the configuration file `config_path`); else
/// history::kDefaultDatabase in the current folder.
std::filesystem::path history_database_path(const std::string& option, const Scenario* scenario,
                                            const std::string& config_path);

/// A run's date (ISO 8601, UTC) and where it came from ("option", "metadata", "file time").
struct RunDate {
  std::string date, source;
};

/// The date of a run (docs/history.md, "The run's date"): `date_option` (--date) when given; else the
/// record's `date` metadata (`metadata`, when the record's head could be read; `record_name` names it); else
/// the modification time, in UTC, of the record file at `record_file` (empty: none). Throws gyrocal::Error
/// naming
/// --date for a bad --date, the record for a bad metadata date, and asking for --date when there is no date.
RunDate run_date(const std::string& date_option, const RecordMetadata* metadata,
                 const std::string& record_name, const std::string& record_file);

/// The checks of --unit, --note and --date before any work (the database checks them again when it adds):
/// the serial's and the note's lengths (limits::kHistoryUnitBytes, kHistoryNoteBytes), a date that exists.
void check_run_options(const std::string& unit, const std::string& note, const std::string& date);

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
void register_history(CLI::App& app);

}  // namespace gyrocal::cli
