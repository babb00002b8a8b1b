// gyrocal calibrate RECORD: reduce a record and identify the drift coefficients; with --history, store the
// run in the calibration history (docs/history.md).
#include <sys/stat.h>

#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/history/database.hpp"
#include "gyrocal/history/run.hpp"
#include "gyrocal/history/sha256.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/imu_calibration.hpp"
#include "gyrocal/identify/record_check.hpp"
#include "gyrocal/identify/scenario_options.hpp"
#include "gyrocal/identify/unknowns.hpp"
#include "gyrocal/report/html_report.hpp"
#include "gyrocal/result/calibration_json.hpp"
#include "gyrocal/result/imu_calibration_json.hpp"
#include "gyrocal/result/test_statement_json.hpp"
#include "tables.hpp"

namespace gyrocal::cli {

void register_calibrate(CLI::App& app) {
  struct Options {
    std::string record, config, json, method = "least-squares", compensation = "full", estimate;
    std::string gyro_model;                 // empty: [calibration] gyro_model
    std::string reduction;                  // empty: [calibration] reduction
    std::string history, unit, date, note;  // --history FILE --unit SERIAL [--date D] [--note T]
    bool force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("calibrate",
                                     "Reduce a record and identify the sensor's coefficients (a gyro's drift "
                                     "coefficients, an accelerometer's IEEE 1293 coefficients)");
  sub->add_option("RECORD", opt->record, "Test record (CSV, docs/contract.md)")->required();
  sub->add_option(
      "--config", opt->config,
      "Configuration file (TOML): the machine, site and plan of the test, and the record's layout "
      "([record])");
  sub->add_option(
         "--method", opt->method,
         "closed-form (a gyro's 16-position test) or least-squares (default; an accelerometer's only)")
      ->check(CLI::IsMember({"closed-form", "least-squares"}));
  sub->add_option("--compensation", opt->compensation, kCompensationHelp)
      ->check(CLI::IsMember({"none", "seed", "full"}));
  sub->add_option("--reduction", opt->reduction,
                  "harmonic (harmonic fit in gamma with a linear trend in time) or window (mean around each "
                  "gamma); default: "
                  "[calibration] reduction, else harmonic")
      ->check(CLI::IsMember({"harmonic", "window"}));
  sub->add_option(
      "--estimate", opt->estimate,
      "Machine errors estimated from the data with the coefficients, NAME[,NAME...] (NAME, NAME_I/_O/_S, "
      "NAME:N for a harmonic; docs/self_calibration.md); overrides [calibration] estimate");
  add_gyro_model_option(sub, opt->gyro_model);
  sub->add_option("--json", opt->json, "Write the result as JSON to FILE ('-' = standard output)");
  add_force_flag(sub, opt->force);
  sub->add_option(
      "--history", opt->history,
      "Store the run in this history database (SQLite; created if missing; docs/history.md), with "
      "--unit");
  sub->add_option("--unit", opt->unit, "With --history: the calibrated unit's serial");
  const CLI::Option* date_option =
      sub->add_option("--date", opt->date,
                      "With --history: the run's date, YYYY-MM-DD[THH:MM:SS] in UTC; default: the record's "
                      "'# date = ...' metadata, else the record file's time");
  sub->add_option("--note", opt->note, "With --history: a note kept with the run");
  sub->callback([opt, date_option] {
    if (date_option->count() > 0 && opt->date.empty())
      throw Error("--date is empty: give the run's date as YYYY-MM-DD[THH:MM:SS], or leave --date out.");
    // --history and --unit go together; --date and --note only with them (docs/history.md).
    const bool storing = !opt->history.empty();
    if (storing && opt->unit.empty())
      throw Error(
          "--history needs --unit SERIAL: the serial of the unit calibrated, which the run is stored under.");
    if (!storing && !opt->unit.empty())
      throw Error("--unit is the serial a run is stored under in the history: give --history FILE with it.");
    if (!storing && (!opt->date.empty() || !opt->note.empty()))
      throw Error(
          fmt::format("{} is kept with a run in the history: give --history FILE --unit SERIAL with it.",
                      !opt->date.empty() ? "--date" : "--note"));
    refuse_to_overwrite_input(opt->json, opt->record);
    refuse_to_overwrite_input(opt->json, opt->config);
    check_output(opt->json, OutputKind::kResult, opt->force, "--json");
    std::string record_sha256, config_sha256;
    std::optional<history::Database> db;
    if (storing) {
      check_run_options(opt->unit, opt->note, opt->date);
      refuse_to_overwrite_input(opt->history, opt->record);
      refuse_to_overwrite_input(opt->history, opt->config);
      if (opt->history == opt->json)
        throw Error(fmt::format("--history and --json name the same file {}.", opt->history));
      // The record's SHA-256 identifies the run: the record must be a file that can be read again.
      struct stat st {};
      if (::stat(opt->record.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
        throw Error(
            fmt::format("--history: the record {} is not a regular file (a pipe or a device): its SHA-256 "
                        "identifies the run in the history, so give the record as a file.",
                        opt->record));
      // The database is opened (created if missing) and checked before the calibration's work.
      db.emplace(history_database_path(opt->history, nullptr, ""), history::Database::Mode::kCreateWrite);
      record_sha256 = history::sha256_file(opt->record, "record");
      if (!opt->config.empty()) config_sha256 = history::sha256_file(opt->config, "configuration file");
    }
    const Scenario s = load_configuration(opt->config);
    // The options as the library builds them for every caller (identify/scenario_options.hpp).
    CalibrationChoices choices;
    choices.method = opt->method;
    choices.compensation = opt->compensation;
    if (!opt->estimate.empty()) choices.estimate = split_names(opt->estimate);
    choices.gyro_model = opt->gyro_model;
    choices.reduction = opt->reduction;
    const CalibrationOptions options = calibration_options(s, choices);
    check_feasible(s, opt->config, options.reduce);
    if (s.is_imu()) {
      // A whole IMU (docs/imu.md): every channel's column in one pass, one joint solve.
      if (storing)
        throw Error(
            "--history does not store an IMU's calibration yet: its history holds one sensor's "
            "coefficients per run (docs/history.md); leave --history out.");
      const std::optional<RecordLayout> layout = s.reading_layout();
      require_angle_columns(layout, opt->record);
      RecordReader reader(opt->record, layout);
      const ImuCalibrationResult r = calibrate_imu_record(reader, s.channels(), s.model(), s.test, options);
      if (!opt->json.empty()) {
        nlohmann::ordered_json j = imu_calibration_to_json(r);
        j["record"] = opt->record;
        j["config"] = opt->config.empty() ? nlohmann::json(nullptr) : nlohmann::json(opt->config);
        j["plan"] = plan_to_json(s.test);
        write_result(opt->json, j, "calibration", opt->force);
      }
      if (opt->json != "-") print_out("{}", imu_result_table(r));
      return;
    }
    require_angle_columns(s.record, opt->record);
    // The record's output column and metadata against the configuration, before its rows are read
    // (docs/interface.md). The record is opened once: the reader that read its head reads its rows (a pipe,
    // a FIFO or /dev/stdin can be read only once).
    const std::string config_name = opt->config.empty() ? "the built-in scenario" : opt->config;
    RecordReader reader(opt->record, s.record);
    require_output_for_sensor(reader, s.sensor_kind, config_name);
    const std::vector<std::string> metadata_warnings =
        check_record_metadata(reader.metadata(), opt->record, s, config_name);
    for (const std::string& w : metadata_warnings) fmt::print(stderr, "gyrocal: warning: {}\n", w);
    // The run's date, before the rows are read: --date, else the record's metadata, else its file's time.
    std::optional<RunDate> date;
    if (storing) date = run_date(opt->date, &reader.metadata(), opt->record, opt->record);
    CalibrationResult r = calibrate_record(reader, s.model(), s.test, options);
    r.warnings.insert(r.warnings.begin(), metadata_warnings.begin(), metadata_warnings.end());
    nlohmann::ordered_json j;
    if (!opt->json.empty() || storing) {
      j = calibration_to_json(r);
      // Provenance (docs/interface.md): the record, the configuration (null: the built-in scenario), the
      // plan; with --history, the SHA-256 of the record and of the configuration (docs/history.md).
      j["record"] = opt->record;
      j["config"] = opt->config.empty() ? nlohmann::json(nullptr) : nlohmann::json(opt->config);
      j["plan"] = plan_to_json(s.test);
      if (storing) {
        j["record_sha256"] = record_sha256;
        j["config_sha256"] = config_sha256.empty() ? nlohmann::json(nullptr) : nlohmann::json(config_sha256);
      }
    }
    // What the report states beyond the estimates (docs/report.md): the unit under test, the record's truth,
    // the g-levels and sequence; its warnings (a [unit] serial the record contradicts) printed too.
    nlohmann::ordered_json scratch;
    const std::vector<std::string> statement_warnings = add_test_statement(
        !opt->json.empty() || storing ? j : scratch, s, &reader.metadata(), r.positions, opt->record);
    r.warnings.insert(r.warnings.end(), statement_warnings.begin(), statement_warnings.end());
    if (!opt->json.empty()) write_result(opt->json, j, "calibration", opt->force);
    if (opt->json != "-") print_out("{}", result_table(r));
    if (storing) {
      // The JSON above is written first: a refused add (the same record stored before) leaves it in place.
      mark_result(j, "calibration");
      const std::string text = j.dump(2) + "\n";
      history::Run run = history::run_from_result(nlohmann::json::parse(text), opt->record);
      run.unit = opt->unit;
      run.note = opt->note;
      run.date = date->date;
      run.date_source = date->source;
      run.record_sha256 = record_sha256;
      run.config_sha256 = config_sha256;
      const std::int64_t id = db->add(run, text);
      const std::string line =
          fmt::format("added run {} of unit {} ({}) to {}\n", id, run.unit, run.date, db->path().string());
      if (opt->json == "-")
        fmt::print(stderr, "{}", line);
      else
        print_out("{}", line);
    }
  });
}

}  // namespace gyrocal::cli
