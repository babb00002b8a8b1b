#pragma once
// One calibration run of one unit as the calibration history keeps it (docs/history.md): who (the unit's
// serial), when (the record's date), from what (the record's and the configuration's SHA-256, gyrocal's
// version), and what came out (every coefficient with its standard uncertainty and identifiability, the
// machine errors the run estimated, the misfit verdict and the data quality), read from a calibration result
// (calibrate's JSON, docs/interface.md "Result (JSON)"). No file and no database here: run_from_result()
// reads an already parsed result; history/database.hpp stores and loads runs.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace gyrocal::history {

/// One estimated quantity of one channel of a run: a coefficient (dF, K1, ...) in the result's own unit.
/// `value` and `std` are absent where the run could not identify it (its result writes null).
struct CoefficientValue {
  std::string
      channel;       ///< the channel: a lone sensor's kind ("gyro", "accelerometer"), an IMU's channel name
  std::string name;  ///< the coefficient's key in the result ("dF", "K1", "scale_factor_error_ppm", ...)
  std::optional<double> value;
  std::optional<double> std;  ///< standard uncertainty, same unit
  std::string unit;           ///< as the result writes it ("deg/h/g", "ug", ...)
  bool identifiable = false;
};

/// One machine error a run estimated (calibrate --estimate): the shared rig's, not the unit's.
struct MachineErrorValue {
  /// The error's name for the history: `error` as in --estimate, with ":N:cos" / ":N:sin" for a harmonic's
  /// part (e.g. "radius_error", "counter_wobble_x:2:cos").
  std::string name;
  std::optional<double> value;
  std::optional<double> std;
  std::string unit;  ///< arcsec, m, rad/s, ... as the result writes it
};

/// The run's data quality and misfit verdict, as the result states them.
struct RunQuality {
  std::int64_t rows_read = 0;
  std::int64_t rows_used = 0;
  std::int64_t outliers = 0;
  std::int64_t gaps = 0;
  bool misfit_tested = false;
  std::optional<double> misfit_p_value;
  double std_scale = 1.0;  ///< the factor the misfit rule applied to the stated σ (1: none)
};

/// One calibration run of one unit.
struct Run {
  std::int64_t id = 0;  ///< the database's id (0 until stored)
  std::string unit;     ///< the unit's serial, as given (--unit)
  /// The record's date, ISO 8601 in UTC: "YYYY-MM-DD" or "YYYY-MM-DDTHH:MM:SS".
  std::string date;
  /// Where the date came from: "option" (--date), "metadata" (the record's `# date = ...`), "file time".
  std::string date_source;
  std::string sensor;                 ///< "gyro", "accelerometer" (later "imu")
  std::vector<std::string> channels;  ///< the channel names, in the result's order (a lone sensor: {sensor})
  std::string record_path;            ///< as the result names it
  std::string record_sha256;          ///< 64 lower-case hex digits
  std::string config_sha256;          ///< of the configuration file's bytes; "" for the built-in scenario
  std::string gyrocal_version;        ///< of the gyrocal that calibrated (the result's gyrocal.version)
  std::string method;                 ///< "least-squares", "closed-form"
  std::string compensation;           ///< "none", "seed", "full"
  std::string note;                   ///< --note, may be empty
  std::vector<CoefficientValue> coefficients;
  std::vector<MachineErrorValue> machine_errors;
  RunQuality quality;
};

/// Days since 1970-01-01T00:00:00 UTC of an ISO date "YYYY-MM-DD" or "YYYY-MM-DDTHH:MM:SS" (a trailing "Z" is
/// taken), the time axis of trends. Throws gyrocal::Error naming `what` (e.g. "--date") for any other text or
/// a date that does not exist (2026-02-30), or one outside the years 1900-9999.
double days_since_epoch(std::string_view iso_date, std::string_view what);

/// True when `text` is well-formed UTF-8 (no overlong form, no surrogate, nothing above U+10FFFF): what a
/// unit's serial and a run's note must be, since JSON, the report and a terminal show them.
bool valid_utf8(std::string_view text);

/// The run stated by a calibration result (calibrate's JSON): sensor, channels, coefficients, machine errors,
/// misfit and data quality, gyrocal's version, method and compensation, the record's path and (when the
/// result holds them) `record_sha256` and `config_sha256`. unit, date, date_source and note are left for the
/// caller, and so are record_sha256 / config_sha256 when the result lacks them. Throws gyrocal::Error naming
/// `result_name` and the key for a result that is not a calibration result (its `gyrocal.result` is not
/// "calibration"), lacks coefficients, or holds a value of the wrong type.
Run run_from_result(const nlohmann::json& result, std::string_view result_name);

}  // namespace gyrocal::history
