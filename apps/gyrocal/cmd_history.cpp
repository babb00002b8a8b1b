// gyrocal history add RESULT.json --unit SERIAL: store a calibration run in the calibration history
// (docs/history.md), and what calibrate --history shares with it: the database's path, the run's date.
#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/history/database.hpp"
#include "gyrocal/history/run.hpp"
#include "gyrocal/history/sha256.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/report/html_report.hpp"
#include "history_show.hpp"

namespace gyrocal::cli {

namespace fs = std::filesystem;

fs::path history_database_path(const std::string& option, const Scenario* scenario,
                               const std::string& config_path) {
  if (!option.empty()) return option;
  if (scenario != nullptr && !scenario->history_database.empty()) {
    const fs::path db = scenario->history_database;
    if (db.is_absolute() || config_path.empty()) return db;
    return fs::path(config_path).parent_path() / db;
  }
  return history::kDefaultDatabase;
}

namespace {

/// The ISO date as the history keeps it: "T" upper case, no "Z".
std::string normalised_date(std::string date) {
  if (!date.empty() && (date.back() == 'Z' || date.back() == 'z')) date.pop_back();
  if (date.size() > 10) date[10] = 'T';
  return date;
}

/// The modification time of the regular file at `path`, ISO 8601 in UTC; "" if it has none (missing, not a
/// regular file).
std::string file_time_utc(const std::string& path) {
  struct stat st {};
  if (path.empty() || ::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return "";
  std::tm tm{};
  const std::time_t t = st.st_mtime;
  if (gmtime_r(&t, &tm) == nullptr) return "";
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  return buf;
}

}  // namespace

RunDate run_date(const std::string& date_option, const RecordMetadata* metadata,
                 const std::string& record_name, const std::string& record_file) {
  if (!date_option.empty()) {
    history::days_since_epoch(date_option, "--date");
    return {normalised_date(date_option), "option"};
  }
  if (metadata != nullptr) {
    for (const auto& [key, value] : *metadata) {
      if (key != "date") continue;
      try {
        history::days_since_epoch(value,
                                  fmt::format("{}: its metadata line '# date = {}'", record_name, value));
      } catch (const Error& e) {
        std::string what = e.what();
        if (!what.empty() && what.back() == '.') what.pop_back();
        throw Error(what + "; correct it, or give the run's date with --date.");
      }
      return {normalised_date(value), "metadata"};
    }
  }
  const std::string time = file_time_utc(record_file);
  if (!time.empty()) {
    history::days_since_epoch(time, "the record file's time");
    return {time, "file time"};
  }
  throw Error(
      fmt::format("Cannot date the run: {} holds no '# date = ...' metadata and {}; give the run's date "
                  "with --date YYYY-MM-DD[THH:MM:SS] (UTC).",
                  record_name.empty() ? std::string("the record") : record_name,
                  record_file.empty() ? std::string("no record file can be read for its time")
                                      : fmt::format("the file {} cannot be read for its time", record_file)));
}

void check_run_options(const std::string& unit, const std::string& note, const std::string& date) {
  if (unit.size() > limits::kHistoryUnitBytes)
    throw Error(
        fmt::format("--unit: the serial is {} bytes long, longer than {} (limits::kHistoryUnitBytes).",
                    unit.size(), limits::kHistoryUnitBytes));
  if (unit.find_first_not_of(" \t") == std::string::npos)
    throw Error("--unit: the unit's serial is empty; give the serial of the unit calibrated.");
  for (const char c : unit)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      throw Error(
          "--unit: the serial holds a control character (a tab, a line break, ...); write it on one line.");
  if (note.size() > limits::kHistoryNoteBytes)
    throw Error(fmt::format("--note: the note is {} bytes long, longer than {} (limits::kHistoryNoteBytes).",
                            note.size(), limits::kHistoryNoteBytes));
  if (!date.empty()) history::days_since_epoch(date, "--date");
}

namespace {

/// The configuration a result was calibrated with, for the record's layout, [history] database and the
/// configuration's SHA-256: `--config` when given (it must load), else the result's `config` path when that
/// file exists (it must load too), else none (the built-in scenario, or a configuration no longer there).
struct ResultConfiguration {
  std::optional<Scenario> scenario;
  std::string path;  ///< the file read, "" for none
};

ResultConfiguration configuration_of(const std::string& option, const nlohmann::json& result) {
  ResultConfiguration c;
  if (!option.empty()) {
    c.path = option;
  } else if (const auto it = result.find("config"); it != result.end() && it->is_string()) {
    std::error_code ec;
    if (fs::is_regular_file(it->get<std::string>(), ec)) c.path = it->get<std::string>();
  }
  if (!c.path.empty()) c.scenario = load_configuration(c.path);
  return c;
}

}  // namespace

void register_history(CLI::App& app) {
  CLI::App* history = app.add_subcommand("history", "The calibration history of units (an SQLite database)");
  history->require_subcommand(1, 1);

  struct AddOptions {
    std::string result, unit, db, date, note, record, config;
  };
  auto opt = std::make_shared<AddOptions>();
  CLI::App* add =
      history->add_subcommand("add", "Store a calibration result (calibrate --json) as a run of a unit");
  add->add_option("RESULT", opt->result, "Calibration result (JSON) written by calibrate --json")->required();
  add->add_option("--unit", opt->unit, "The calibrated unit's serial")->required();
  add->add_option("--db", opt->db,
                  "History database (SQLite; created if missing); default: [history] database of the "
                  "configuration, else gyrocal-history.sqlite in the current folder");
  const CLI::Option* date_option = add->add_option(
      "--date", opt->date,
      "The run's date, YYYY-MM-DD[THH:MM:SS] in UTC; default: the record's '# date = ...' metadata, "
      "else the record file's time");
  add->add_option("--note", opt->note, "A note kept with the run (e.g. 'after the shock test')");
  add->add_option(
      "--record", opt->record,
      "The record the result was calibrated from, for its SHA-256 and date, when the result does not "
      "hold its SHA-256 or names a record path that is not there");
  add->add_option("--config", opt->config,
                  "The configuration the result was calibrated with (for a rig's record layout and [history] "
                  "database); default: the result's config path, if readable");
  add->callback([opt, date_option] {
    if (date_option->count() > 0 && opt->date.empty())
      throw Error("--date is empty: give the run's date as YYYY-MM-DD[THH:MM:SS], or leave --date out.");
    check_run_options(opt->unit, opt->note, opt->date);
    const nlohmann::json result = read_result_file(opt->result);
    history::Run run = history::run_from_result(result, opt->result);
    run.unit = opt->unit;
    run.note = opt->note;
    const ResultConfiguration config = configuration_of(opt->config, result);
    if (run.config_sha256.empty() && !config.path.empty())
      run.config_sha256 = history::sha256_file(config.path, "configuration file");

    // The record: its SHA-256 identifies the run; its metadata or file time dates it.
    const std::string record_file = !opt->record.empty() ? opt->record : run.record_path;
    if (!run.record_sha256.empty()) {
      if (!history::is_sha256_hex(run.record_sha256))
        throw Error(fmt::format("{}: record_sha256 '{}' is not a SHA-256 (64 lower-case hexadecimal digits).",
                                opt->result, run.record_sha256.substr(0, 80)));
    } else if (record_file.empty()) {
      throw Error(
          fmt::format("{} names no record and holds no record_sha256: give the record it was calibrated "
                      "from with --record FILE (its SHA-256 identifies the run).",
                      opt->result));
    } else {
      try {
        run.record_sha256 = history::sha256_file(record_file, "record");
      } catch (const Error& e) {
        std::string what = e.what();
        if (!what.empty() && what.back() == '.') what.pop_back();
        throw Error(what +
                    (opt->record.empty()
                         ? fmt::format(" (the record {} names); give the record with --record FILE (its "
                                       "SHA-256 identifies the run).",
                                       opt->result)
                         : std::string(" (--record).")));
      }
    }
    std::optional<RecordMetadata> metadata;
    if (opt->date.empty() && !record_file.empty()) {
      std::error_code ec;
      if (fs::is_regular_file(record_file, ec)) {
        // Only the head is read: the magic line (gyrocal's format), the metadata and the header.
        const std::optional<RecordLayout> layout = config.scenario ? config.scenario->record : std::nullopt;
        try {
          RecordReader reader(record_file, layout);
          metadata = reader.metadata();
        } catch (const Error& e) {
          fmt::print(stderr,
                     "gyrocal: warning: the record's metadata could not be read ({}); the run is dated by "
                     "the file's time.\n",
                     e.what());
        }
      }
    }
    const RunDate date = run_date(opt->date, metadata ? &*metadata : nullptr, record_file, record_file);
    run.date = date.date;
    run.date_source = date.source;

    const fs::path db_path =
        history_database_path(opt->db, config.scenario ? &*config.scenario : nullptr, config.path);
    history::Database db(db_path, history::Database::Mode::kCreateWrite);
    const std::int64_t id = db.add(run, result.dump());
    print_out("added run {} of unit {} ({}, from the {}) to {}\n", id, run.unit, run.date,
              date.source == "option"     ? "--date option"
              : date.source == "metadata" ? "record's metadata"
                                          : "record file's time",
              db_path.string());
  });
  register_history_show(*history);  // history show (cmd_history_show.cpp)
}

}  // namespace gyrocal::cli
