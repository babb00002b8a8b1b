#pragma once
// The report's writing helpers (docs/report.md), private to src/report: escaping every string that comes from
// a result, reading a result's sections with a sentence for each thing that is wrong, numbers as text,
// colours and HTML tables. No section and no page layout here.
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace gyrocal::report {

using nlohmann::json;

// ---------------------------------------------------------------------------------------------
// Escaping: every string that comes from a result goes through one of these.

/// Text as HTML: & < > " ' escaped.
std::string esc(std::string_view text);

/// JSON that is safe inside <script type="application/json">: '<', '>' and '&' only occur inside JSON
/// strings, where their \u escapes mean the same, so "</script>" and "<!--" cannot appear.
std::string json_for_script(const json& value);

// ---------------------------------------------------------------------------------------------
// Reading a result: a section that does not have the expected shape throws gyrocal::Error with a sentence
// saying what is wrong; the page then shows that sentence in place of the section (Page::section).

std::string type_name(const json& j);
/// object[key]; throws naming `where` when `object` is not an object or has no `key`.
const json& member(const json& object, std::string_view key, std::string_view where);
/// object[key], or null when `object` is not an object or has no `key`.
const json* find(const json& object, std::string_view key);
/// Throws naming `where` unless `j` is of `type` (number_float stands for any number).
void expect(const json& j, json::value_t type, std::string_view where);
/// A number, or nothing for null (NaN and infinities are written as null) or a missing key.
std::optional<double> number(const json& object, std::string_view key, std::string_view where);
std::optional<double> number(const json& j, std::string_view where);
/// A string member as it is, any other value as compact JSON, `fallback` when missing or null.
std::string string_or(const json& object, std::string_view key, std::string_view fallback = "");
/// `text` as it is when it has at most `max_bytes` bytes, else its first bytes (whole UTF-8 characters) and
/// an ellipsis: for a text from the result that a table or plot repeats in many cells (a row's label in each
/// of its cells), so that the page grows with the cells, not with the cells times the text. A gyrocal name
/// or unit has a few dozen bytes.
std::string short_text(std::string_view text, std::size_t max_bytes = 120);
/// Any JSON value as text: strings unquoted, anything else as compact JSON.
std::string scalar_text(const json& j);
/// Any JSON value for a reader: strings unquoted, numbers with 6 significant digits, booleans yes/no, null a
/// dash, objects as "key: value, ..." and arrays as "a, b, ..." (recursively).
std::string value_text(const json& j);

/// Names in the order of docs/physics.md (the coefficients, the gyro model's scale factor and misalignments,
/// the closed form's alternatives, the combinations of section 8), then the accelerometer's in IEEE Std
/// 1293's table order (K0 K1 K2 K3 Kip Kio Kpo Kpp Koo delta_p delta_o), then any other names alphabetically.
/// nlohmann::json objects are sorted, so the order must be imposed here.
std::vector<std::string> ordered_names(const std::set<std::string>& names);
std::vector<std::string> ordered_keys(const json& object);

// ---------------------------------------------------------------------------------------------
// Numbers as text.

extern const char* const kDash;  ///< em dash: no value

std::string num(std::optional<double> v, int significant = 6);
/// Decimals that show a standard uncertainty with two significant digits (-1 when there is none).
int decimals_for(std::optional<double> std_dev);
std::string fixed(std::optional<double> v, int decimals);
/// "value ± std" with the decimals of decimals_for(std).
std::string value_pm(std::optional<double> v, std::optional<double> s);
json opt_json(std::optional<double> v);

// ---------------------------------------------------------------------------------------------
// Colours.

/// Diverging colour (blue for negative, red for positive, near-white at zero) for c in [-1, 1].
std::string diverging_colour(double c);
/// The i-th colour of a categorical palette (repeats after 12).
std::string palette(std::size_t i);

// ---------------------------------------------------------------------------------------------
// Tables.

struct Cell {
  std::string html;  ///< already escaped
  bool numeric = false;
  std::string cls;    ///< extra class
  std::string title;  ///< tooltip, plain text (escaped by table())
};

Cell text_cell(std::string_view text);
Cell num_cell(std::string text, std::string cls = "", std::string title = "");
/// A cell for a field of unknown type: a dash when absent (nullptr), a number cell for a number, text else.
Cell value_cell(const json* v);

/// The bound on every table (and heat map) the report draws (limits::kReportTableCells; issue 29): throws
/// gyrocal::Error naming `where` (the part of the result drawn), its `rows` x `columns` and the limit when
/// they make more cells than the limit. Called before any row is built, with rows and columns counted from
/// the array's length and the union of its entries' keys, so that a table's memory stays bounded whatever
/// the result; the section then shows the sentence in its place (Page::section) and the page is still drawn.
void check_table_cells(std::size_t rows, std::size_t columns, std::string_view where);

/// An HTML table (header cells are escaped here; long names may break after an underscore). Throws as
/// check_table_cells when it has more cells than limits::kReportTableCells (a table built without that check
/// first).
std::string table(const std::vector<std::string>& header, const std::vector<std::vector<Cell>>& rows,
                  std::string_view cls = "");

/// A table of an array of objects whose fields are not all known: the `first` fields in that order, then
/// every other field that any entry has, alphabetically; numbers right-aligned, anything else as scalar_text.
/// Throws naming `where` when `entries` is not an array of objects, or when its entries x columns are more
/// cells than limits::kReportTableCells (checked before any cell is built).
std::string generic_table(const json& entries, const std::vector<std::string>& first, std::string_view where);

}  // namespace gyrocal::report
