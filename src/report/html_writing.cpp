// The report's writing helpers (html_writing.hpp, docs/report.md).
#include "html_writing.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"

namespace gyrocal::report {

std::string esc(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string json_for_script(const json& value) {
  const std::string dumped = value.dump(-1, ' ', false, json::error_handler_t::replace);
  std::string out;
  out.reserve(dumped.size());
  for (const char c : dumped) {
    switch (c) {
      case '<':
        out += "\\u003c";
        break;
      case '>':
        out += "\\u003e";
        break;
      case '&':
        out += "\\u0026";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string type_name(const json& j) {
  return std::string(j.type_name());
}

const json& member(const json& object, std::string_view key, std::string_view where) {
  if (!object.is_object())
    throw Error(fmt::format("{} is a JSON {}, not an object", where, type_name(object)));
  const auto it = object.find(key);
  if (it == object.end()) throw Error(fmt::format("{} has no \"{}\"", where, key));
  return *it;
}

const json* find(const json& object, std::string_view key) {
  if (!object.is_object()) return nullptr;
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

void expect(const json& j, json::value_t type, std::string_view where) {
  const bool ok = type == json::value_t::number_float ? j.is_number() : j.type() == type;
  if (!ok)
    throw Error(fmt::format("{} is a JSON {}, not {}", where, type_name(j),
                            type == json::value_t::array    ? "an array"
                            : type == json::value_t::object ? "an object"
                            : type == json::value_t::string ? "a string"
                                                            : "a number"));
}

std::optional<double> number(const json& object, std::string_view key, std::string_view where) {
  const json* j = find(object, key);
  if (j == nullptr || j->is_null()) return std::nullopt;
  if (!j->is_number())
    throw Error(fmt::format("{}.{} is a JSON {}, not a number", where, key, type_name(*j)));
  const double v = j->get<double>();
  return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

std::optional<double> number(const json& j, std::string_view where) {
  if (j.is_null()) return std::nullopt;
  if (!j.is_number()) throw Error(fmt::format("{} is a JSON {}, not a number", where, type_name(j)));
  const double v = j.get<double>();
  return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

std::string string_or(const json& object, std::string_view key, std::string_view fallback) {
  const json* j = find(object, key);
  if (j == nullptr || j->is_null()) return std::string(fallback);
  if (j->is_string()) return j->get<std::string>();
  return j->dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string short_text(std::string_view text, std::size_t max_bytes) {
  if (text.size() <= max_bytes) return std::string(text);
  std::size_t end = max_bytes;
  // Back to the first byte of a UTF-8 character (continuation bytes are 10xxxxxx).
  while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
  return std::string(text.substr(0, end)) + "\xE2\x80\xA6";
}

std::string scalar_text(const json& j) {
  if (j.is_string()) return j.get<std::string>();
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string value_text(const json& j) {
  if (j.is_string()) return j.get<std::string>();
  if (j.is_null()) return kDash;
  if (j.is_boolean()) return j.get<bool>() ? "yes" : "no";
  if (j.is_number()) {
    const double v = j.get<double>();
    return std::isfinite(v) ? num(v) : kDash;
  }
  std::string out;
  if (j.is_object()) {
    for (const auto& [k, v] : j.items()) out += (out.empty() ? "" : ", ") + k + ": " + value_text(v);
  } else {
    for (const auto& v : j) out += (out.empty() ? "" : ", ") + value_text(v);
  }
  return out.empty() ? kDash : out;
}

std::vector<std::string> ordered_names(const std::set<std::string>& names) {
  static const std::vector<std::string> canonical = {
      "dF", "dI", "dO", "dS", "dII", "dOO", "dSS", "dIO", "dIS", "dOS", "scale_factor_error_ppm",
      "input_axis_misalignment_O_arcsec", "input_axis_misalignment_S_arcsec", "dI_1g", "dO_1g", "dS_1g",
      "dIS_b", "dII-dSS", "dOO-dSS", "dF+(1+Ar^2)dSS",
      // The accelerometer's, in IEEE Std 1293's table order.
      "K0", "K1", "K2", "K3", "Kip", "Kio", "Kpo", "Kpp", "Koo", "delta_p", "delta_o"};
  std::vector<std::string> out;
  for (const auto& n : canonical)
    if (names.count(n)) out.push_back(n);
  for (const auto& n : names)
    if (std::find(canonical.begin(), canonical.end(), n) == canonical.end()) out.push_back(n);
  return out;
}

std::vector<std::string> ordered_keys(const json& object) {
  std::set<std::string> names;
  for (const auto& [k, v] : object.items()) names.insert(k);
  return ordered_names(names);
}

const char* const kDash = "\xE2\x80\x94";

std::string num(std::optional<double> v, int significant) {
  if (!v) return kDash;
  return fmt::format("{:.{}g}", *v, significant);
}

int decimals_for(std::optional<double> std_dev) {
  if (!std_dev || *std_dev <= 0.0) return -1;
  const int d = 1 - static_cast<int>(std::floor(std::log10(*std_dev)));
  return std::clamp(d, 0, 12);
}

std::string fixed(std::optional<double> v, int decimals) {
  if (!v) return kDash;
  if (decimals < 0) return num(v);
  return fmt::format("{:.{}f}", *v, decimals);
}

std::string value_pm(std::optional<double> v, std::optional<double> s) {
  if (!v) return kDash;
  const int d = decimals_for(s);
  if (d < 0) return num(v);
  return fmt::format("{:.{}f} \xC2\xB1 {:.{}f}", *v, d, *s, d);
}

json opt_json(std::optional<double> v) {
  return v ? json(*v) : json(nullptr);
}

std::string diverging_colour(double c) {
  const double t = std::clamp(std::fabs(c), 0.0, 1.0);
  const double base[3] = {247, 247, 247};
  const double blue[3] = {33, 102, 172}, red[3] = {178, 24, 43};
  const double* end = c < 0 ? blue : red;
  int rgb[3];
  for (int k = 0; k < 3; ++k) rgb[k] = static_cast<int>(std::lround(base[k] + (end[k] - base[k]) * t));
  return fmt::format("rgb({},{},{})", rgb[0], rgb[1], rgb[2]);
}

namespace {
const char* const kPalette[] = {"#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f", "#edc948",
                                "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac", "#1b9e77", "#7570b3"};
}  // namespace

std::string palette(std::size_t i) {
  return kPalette[i % (sizeof kPalette / sizeof kPalette[0])];
}

Cell text_cell(std::string_view text) {
  return {esc(text), false, "", ""};
}

Cell value_cell(const json* v) {
  if (v == nullptr) return text_cell(kDash);
  if (v->is_number()) return num_cell(value_text(*v));
  return text_cell(value_text(*v));
}

Cell num_cell(std::string text, std::string cls, std::string title) {
  return {esc(text), true, std::move(cls), std::move(title)};
}

void check_table_cells(std::size_t rows, std::size_t columns, std::string_view where) {
  // Neither factor exceeds a result's bytes (64 MiB), so the product fits a 64-bit size.
  const std::size_t cells = rows * columns;
  if (cells <= limits::kReportTableCells) return;
  throw Error(fmt::format(
      "{} would be a table of {} rows \xC3\x97 {} columns, {} cells, more than {}, the limit of a table in "
      "the report (a gyrocal result's largest tables have a few ten thousand cells); it is not drawn",
      where, rows, columns, cells, limits::kReportTableCells));
}

std::string table(const std::vector<std::string>& header, const std::vector<std::vector<Cell>>& rows,
                  std::string_view cls) {
  std::size_t columns = header.size();
  for (const auto& row : rows) columns = std::max(columns, row.size());
  check_table_cells(rows.size(), columns, "a table");
  std::string s = fmt::format("<div class=\"table-wrap\"><table class=\"{}\">\n", cls);
  // A table of label and value (every heading empty) has no heading row.
  const bool headed =
      std::any_of(header.begin(), header.end(), [](const std::string& h) { return !h.empty(); });
  if (headed) s += "<thead><tr>";
  for (const auto& h : header) {
    if (!headed) break;
    // Let long source names such as counter_perpendicularity break after an underscore.
    std::string cell = esc(h);
    for (std::size_t at = cell.find('_'); at != std::string::npos; at = cell.find('_', at + 6))
      cell.replace(at, 1, "_<wbr>");
    s += "<th>" + cell + "</th>";
  }
  if (headed) s += "</tr></thead>\n";
  s += "<tbody>\n";
  for (const auto& row : rows) {
    s += "<tr>";
    for (const auto& c : row) {
      std::string classes = c.numeric ? "num" : "";
      if (!c.cls.empty()) classes += (classes.empty() ? "" : " ") + c.cls;
      s += "<td";
      if (!classes.empty()) s += " class=\"" + classes + "\"";
      if (!c.title.empty()) s += " title=\"" + esc(c.title) + "\"";
      s += ">" + c.html + "</td>";
    }
    s += "</tr>\n";
  }
  return s + "</tbody></table></div>\n";
}

std::string generic_table(const json& entries, const std::vector<std::string>& first,
                          std::string_view where) {
  expect(entries, json::value_t::array, where);
  std::vector<std::string> columns = first;
  std::set<std::string> others;
  for (std::size_t k = 0; k < entries.size(); ++k) {
    expect(entries[k], json::value_t::object, fmt::format("{}[{}]", where, k));
    for (const auto& [key, v] : entries[k].items())
      if (std::find(first.begin(), first.end(), key) == first.end()) others.insert(key);
  }
  columns.insert(columns.end(), others.begin(), others.end());
  check_table_cells(entries.size(), columns.size(), where);
  std::vector<std::vector<Cell>> rows;
  rows.reserve(entries.size());
  for (const auto& e : entries) {
    std::vector<Cell> row;
    for (const auto& column : columns) {
      row.push_back(value_cell(find(e, column)));
    }
    rows.push_back(std::move(row));
  }
  return table(columns, rows, "wrap");
}

}  // namespace gyrocal::report
