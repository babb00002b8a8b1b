#pragma once
// The self-contained HTML report of a result (docs/report.md): tables and plots of every section of a
// result file that is present, in one HTML file that opens with no network. The plots are drawn by
// Chart.js (Debian's libjs-chart.js), whose bundle is compiled into gyrocal and inlined into the page.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace gyrocal {

struct HtmlReportOptions {
  /// Shown as the page title and the first heading; empty = the kind's own ("gyrocal calibration report",
  /// "gyrocal sensitivity report", ...: result_kind).
  std::string title;
  /// Where the result came from (usually its file name), shown in the header; empty = not shown.
  std::string source;
  /// Date and time shown in the header; empty = now, UTC, ISO 8601.
  std::string created;
  /// When not null, receives one sentence per section that is present but could not be read
  /// (that section then shows the same sentence instead of its tables and plots).
  std::vector<std::string>* problems = nullptr;
};

/// Parses the text of a result file as `gyrocal report` reads it: valid JSON that holds an object.
/// Throws gyrocal::Error naming `source_name` otherwise: first, when the first character after white space
/// (and a byte order mark) is not the '{' of an object (naming the character, its line and column); when
/// the text is larger than limits::kResultBytes; on a syntax error (with its line and column); for a number
/// beyond the range of a double; for arrays and objects nested more than limits::kResultDepth levels deep;
/// and for more than limits::kResultNames distinct object keys (core/limits.hpp).
nlohmann::json parse_result_json(std::string_view text, const std::string& source_name);

/// Reads and parses the result file at `path` (any readable file: a regular file, a FIFO, /dev/stdin) as
/// parse_result_json does, naming the file by `path`. At most limits::kResultBytes + 1 bytes are read, and
/// reading stops at the first character if it cannot open a JSON object, so that a record, a huge file or
/// /dev/zero is refused at once and in bounded memory. Throws gyrocal::Error as parse_result_json does, and
/// "Cannot read result file PATH: ..." if the file does not exist, is a directory or cannot be read.
nlohmann::json read_result_file(const std::filesystem::path& path);

/// The key of gyrocal's own marker in every result JSON that gyrocal writes (docs/interface.md, "Files"):
/// `"gyrocal": {"result": KIND, "version": "X.Y.Z"}`. It tells `report` which page to draw and lets `--json`
/// replace an earlier result of gyrocal without --force.
inline constexpr std::string_view kResultMarkerKey = "gyrocal";

/// The kinds of result gyrocal writes, as the marker names them ("history": `history show --json`, a unit's
/// calibration history, which has no page of its own here: report --history draws it from the database).
inline constexpr std::string_view kResultKinds[] = {"calibration", "plan",   "sensitivity", "montecarlo",
                                                    "noise",       "inputs", "history"};

/// Adds gyrocal's marker to `result` (a JSON object): `"gyrocal": {"result": kind, "version": this
/// gyrocal's}`.
void mark_result(nlohmann::json& result, std::string_view kind);
/// The same for a result whose keys keep their written order (calibration_to_json's).
void mark_result(nlohmann::ordered_json& result, std::string_view kind);

/// True when `result` is a JSON object carrying gyrocal's marker with one of kResultKinds.
bool has_result_marker(const nlohmann::json& result);

/// The kind of a result: its marker's, else (a result written before the marker, or by Python) from its
/// shape: `allan` = noise, `rows` without `coefficients` = sensitivity, `budget` or `trials` = montecarlo,
/// `specific_force_g` = inputs, `unit` with `channels` and `runs` = history, anything else a calibration (a
/// calibration, a plan or the demo's result.json).
std::string result_kind(const nlohmann::json& result);

/// Renders the HTML report of `result`, the page of its kind (result_kind): a calibration or plan result (a
/// JSON object with any of the sections of docs/report.md: method/compensation/g_level/warnings, plan,
/// data_quality, coefficients with truth, machine_errors, combinations, alternatives, comparison, positions,
/// sensitivity, montecarlo), a sensitivity study (heat maps), a Monte Carlo run (histograms and budget) or a
/// noise characterisation (render_noise_html_report). Sections that are absent are left out; the
/// navigation lists exactly the sections drawn. Every string from `result` is escaped.
/// Throws gyrocal::Error if `result` is not a JSON object.
std::string render_html_report(const nlohmann::json& result, const HtmlReportOptions& options = {});

/// The names of the report's sections that `result` has (summary, plan, data_quality, coefficients,
/// machine_errors, ...; those of its kind's page), in report order (empty if none: `gyrocal report` then
/// refuses the file).
std::vector<std::string> report_sections_present(const nlohmann::json& result);

/// The first bytes of every report (of a result or of a noise characterisation): an existing file that
/// starts with them is an earlier report, which `gyrocal report` and `gyrocal noise --html` replace without
/// --force (docs/report.md).
inline constexpr std::string_view kReportMarker = "<!DOCTYPE html>\n<!-- gyrocal-report:";

/// The plotting library's bundle as inlined into every report (Chart.js, from libjs-chart.js).
std::string_view embedded_plot_library();

/// This gyrocal's version, as shown in the report's header.
std::string_view gyrocal_version();

}  // namespace gyrocal
