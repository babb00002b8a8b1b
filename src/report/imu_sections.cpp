// The page of an IMU result (imu_report.hpp, docs/report.md "An IMU's result"): the summary of the joint fit,
// the shared machine errors, the triad's geometry, then one section per channel drawn by the lone sensor's
// own renderers (section_renderers.hpp) from a view of the channel shaped as a lone result, then the plan,
// the data quality and the provenance. The result is checked whole first (imu_check.cpp).
#include <cmath>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/report/imu_report.hpp"
#include "html_writing.hpp"
#include "page.hpp"
#include "section_renderers.hpp"

namespace gyrocal {

using nlohmann::json;

namespace report::section {
namespace {

/// The anchor of a channel's section (its name is letters, digits and _ - ., check_imu_result).
std::string channel_anchor(const std::string& name) {
  return "channel-" + name;
}

std::string channel_title(const std::string& name, const json& channel) {
  return fmt::format("Channel {} ({})", name, string_or(channel, "sensor", "?"));
}

/// The channels' names in the order the configuration lists them: the order in which the positions (written
/// channel by channel) first name them, then any channel without a position, alphabetically. A result is
/// read into sorted objects, so the order of its `channels` is not the file's.
std::vector<std::string> channel_order(const json& result) {
  std::vector<std::string> names;
  std::set<std::string> seen;
  const json& channels = result.at("channels");
  if (const json* positions = find(result, "positions"); positions && positions->is_array())
    for (const json& p : *positions)
      if (const json* c = find(p, "channel"); c && c->is_string()) {
        const std::string& name = c->get_ref<const std::string&>();
        if (channels.contains(name) && seen.insert(name).second) names.push_back(name);
      }
  for (const auto& [name, c] : channels.items())
    if (seen.insert(name).second) names.push_back(name);
  return names;
}

/// One channel as a lone sensor's result, so that the lone renderers draw it: its sensor, coefficients,
/// combinations, misfit (with its chi2 and dof where the lone result keeps them), warnings, its own positions
/// and, in a simulated result, its truth.
json channel_view(const json& result, const std::string& name) {
  const json& c = result.at("channels").at(name);
  json view = {{"sensor", c.at("sensor")},
               {"coefficients", c.at("coefficients")},
               {"misfit", c.at("misfit")},
               {"warnings", c.at("warnings")},
               {"positions", json::array()}};
  // The lone result keeps its chi2 and dof beside its misfit, whose further fields the verdict lists.
  for (const char* key : {"chi2", "dof"})
    if (const json* v = find(c.at("misfit"), key)) {
      view[key] = *v;
      view["misfit"].erase(key);
    }
  if (const json* comb = find(c, "combinations"); comb && !comb->empty()) view["combinations"] = *comb;
  for (const json& p : result.at("positions"))
    if (p.at("channel") == name) view["positions"].push_back(p);
  if (const json* truth = find(result, "truth"))
    if (const json* t = find(*truth, name)) view["truth"] = *t;
  return view;
}

/// The summary: what the IMU is (its channels, each linked to its section, with its fit in one line), the
/// joint fit (method, g-level, rank, condition number, iterations), the data's counts and the warnings.
void imu_summary(const json& result, Page&, std::string& out) {
  const json& channels = result.at("channels");
  std::vector<std::vector<Cell>> rows;
  for (const std::string& name : channel_order(result)) {
    const json& c = channels.at(name);
    const json& coefficients = c.at("coefficients");
    std::size_t identifiable = 0;
    for (const auto& [key, e] : coefficients.items())
      identifiable += e.at("identifiable").get<bool>() ? 1 : 0;
    const json& m = c.at("misfit");
    const auto chi2 = number(m, "chi2", "misfit"), dof = number(m, "dof", "misfit");
    const auto p = number(m, "p_value", "misfit"), scale = number(m, "std_scale", "misfit");
    const bool tested = m.at("tested").get<bool>();
    const std::string verdict = !tested ? "not tested"
                                : scale && *scale > 1.0
                                    ? fmt::format("misfit: \xCF\x83 \xC3\x97 {}", num(scale, 3))
                                    : "passed";
    rows.push_back(
        {Cell{"<a href=\"#" + esc(channel_anchor(name)) + "\">" + esc(name) + "</a>", false, "", ""},
         text_cell(c.at("sensor").get<std::string>()),
         num_cell(fmt::format("{} of {}", identifiable, coefficients.size())),
         num_cell(chi2 && dof && *dof > 0 ? num(*chi2 / *dof, 3) : std::string(kDash)), num_cell(num(p, 2)),
         text_cell(verdict), num_cell(num(number(c, "outliers", "channel"))),
         num_cell(std::to_string(c.at("warnings").size()))});
    if (scale && *scale > 1.0) rows.back()[5].cls = "far";
  }
  out += fmt::format(
      "<p>An IMU of {} channels calibrated in one joint fit: every channel's coefficients and the "
      "shared machine errors from one record (docs/imu.md).</p>\n",
      channels.size());
  out += table({"channel", "sensor", "identifiable coefficients", "\xCF\x87\xC2\xB2/dof", "p", "misfit test",
                "outliers", "warnings"},
               rows, "compact");
  std::string dl;
  const auto fact = [&](std::string_view label, const std::string& text) {
    dl += fmt::format("<dt>{}</dt><dd>{}</dd>", esc(label), esc(text));
  };
  if (const json* method = find(result, "method")) fact("Method", method->get<std::string>());
  if (const json* compensation = find(result, "compensation"))
    fact("Compensation", compensation->get<std::string>());
  if (const json* g = find(result, "g_level"); g && !g->is_null())
    fact("g level (Ar)", num(number(*g, "g_level")));
  const auto rank = number(result, "rank", "the result"), unknowns = number(result, "unknowns", "the result");
  fact("Rank", fmt::format("{} of {} unknowns{}", num(rank), num(unknowns),
                           rank && unknowns && *rank < *unknowns ? " (rank deficient)" : " (full rank)"));
  fact("Condition number", num(number(result, "condition_number", "the result"), 4));
  fact("Iterations", num(number(result, "iterations", "the result")));
  if (const json* q = find(result, "data_quality")) {
    const auto count = [&](std::string_view key) { return num(number(*q, key, "data_quality"), 15); };
    fact("Rows read / used", count("rows_read") + " / " + count("rows_used"));
    if (find(*q, "increments_dropped"))
      fact("Rows left out: their increment's interval is unknown (increments_dropped)",
           count("increments_dropped"));
    fact("Samples rejected as outliers", count("outliers"));
    fact("Breaks in the time series inside dwells", count("gaps"));
  }
  out += "<dl class=\"facts\">" + dl + "</dl>\n";
  const json& warnings = result.at("warnings");
  if (warnings.empty()) {
    out += "<p>No warnings of the joint fit.</p>\n";
  } else {
    out += "<div class=\"warnings\"><h3>Warnings of the joint fit</h3><ul>\n";
    for (const json& w : warnings) out += "<li>" + esc(w.get<std::string>()) + "</li>\n";
    out += "</ul></div>\n";
  }
}

/// The shared machine errors (the lone table), and the truth the record was simulated with when the result
/// states it (the demo's `truth_machine`).
void imu_machine_errors(const json& result, Page& page, std::string& out) {
  if (result.at("machine_errors").empty()) {
    out += "<p>No machine error was estimated: every channel was corrected by the configured machine.</p>\n";
    return;
  }
  machine_errors(result, page, out);
  if (const json* truth = find(result, "truth_machine")) {
    std::vector<std::vector<Cell>> rows;
    for (const auto& [key, v] : truth->items())
      rows.push_back({text_cell(key), num_cell(num(number(v, key)))});
    out += "<p class=\"note\">The machine the record was simulated with:</p>\n" +
           table({"", "value"}, rows, "compact");
  }
}

/// The triad's geometry: each pair of channels of one kind whose tilts are fitted, their angle, its nominal
/// and its deviation from nominal ± σ in µrad.
void imu_geometry(const json& result, Page&, std::string& out) {
  const json& angles = result.at("input_axis_angles");
  if (angles.empty()) {
    out += "<p>No two channels of one kind have fitted input-axis tilts: the result states no angle.</p>\n";
    return;
  }
  check_table_cells(angles.size(), 6, "input_axis_angles");
  std::vector<std::vector<Cell>> rows;
  for (std::size_t k = 0; k < angles.size(); ++k) {
    const std::string where = fmt::format("input_axis_angles[{}]", k);
    const json& a = angles[k];
    const auto dev = number(a, "deviation_urad", where), s = number(a, "std_urad", where);
    std::string z = kDash;
    if (dev && s && *s > 0) z = fmt::format("{:+.1f}", *dev / *s);
    rows.push_back({text_cell(a.at("channels")[0].get<std::string>() + " \xE2\x80\x93 " +
                              a.at("channels")[1].get<std::string>()),
                    num_cell(num(number(a, "nominal_deg", where))),
                    num_cell(fixed(number(a, "angle_deg", where), 9)), num_cell(fixed(dev, decimals_for(s))),
                    num_cell(num(s, 2)), num_cell(z)});
  }
  out +=
      "<p class=\"note\">The angle between the fitted input axes of every two channels of one kind (gyros "
      "with "
      "gyros, accelerometers with accelerometers), from their fitted misalignments in the joint fit; the "
      "deviation is the angle less its nominal, in \xC2\xB5rad, with its standard uncertainty \xCF\x83 "
      "(docs/imu.md).</p>\n";
  out += table({"channels", "nominal, deg", "angle, deg", "deviation, \xC2\xB5rad",
                "standard uncertainty \xCF\x83, \xC2\xB5rad", "deviation/\xCF\x83"},
               rows, "compact");
}

/// One channel: its coefficients (the lone table, the truth plot in a simulated result), its fit (the
/// misfit verdict and warnings), its reduced positions with their residuals.
void imu_channel(const json& result, const std::string& name, Page& page, std::string& out) {
  const json view = channel_view(result, name);
  out += "<h3>Coefficients</h3>\n";
  coefficients(view, page, out);
  if (has(view, "combinations")) {
    out += "<h3>Identifiable combinations</h3>\n";
    combinations(view, page, out);
  }
  out += "<h3>Fit</h3>\n";
  summary(view, page, out);
  if (const auto outliers = number(result.at("channels").at(name), "outliers", "channels." + name))
    out += fmt::format("<p>Samples of this channel rejected as outliers: {}.</p>\n", num(outliers));
  out += "<h3>Residuals</h3>\n";
  if (view.at("positions").empty()) {
    out += "<p>The result holds no reduced position of this channel.</p>\n";
    return;
  }
  positions(view, page, out);
}

}  // namespace
}  // namespace report::section

namespace {

/// A section the page draws: its name (as imu_report_sections lists it), anchor and heading, and how.
struct ImuSection {
  std::string name, id, title;
  std::function<void(const json&, report::Page&, std::string&)> render;
};

std::vector<ImuSection> imu_page_sections(const json& result) {
  namespace s = report::section;
  std::vector<ImuSection> out = {
      {"summary", "summary", "Summary", s::imu_summary},
      {"machine_errors", "machine-errors", "Shared machine errors", s::imu_machine_errors},
      {"geometry", "geometry", "The triad's geometry", s::imu_geometry}};
  for (const std::string& name : s::channel_order(result))
    out.push_back({"channel " + name, s::channel_anchor(name),
                   s::channel_title(name, result.at("channels").at(name)),
                   [name = name](const json& r, report::Page& page, std::string& html) {
                     s::imu_channel(r, name, page, html);
                   }});
  if (s::has(result, "plan")) out.push_back({"plan", "plan", "Test plan", s::test_plan});
  if (s::has(result, "data_quality"))
    out.push_back({"data_quality", "data-quality", "Data quality", s::data_quality});
  if (s::has_provenance(result)) out.push_back({"provenance", "provenance", "Provenance", s::provenance});
  return out;
}

}  // namespace

bool is_imu_result(const json& result) {
  if (!result.is_object()) return false;
  const std::string kind = result_kind(result);
  if (kind != "calibration" && kind != "plan") return false;
  // A lone sensor's result has no `channels`: one that has them is an IMU's, checked as one whatever its
  // `sensor` says (check_imu_result refuses any but "imu").
  const auto sensor = result.find("sensor");
  return (sensor != result.end() && *sensor == "imu") || result.contains("channels");
}

std::string render_imu_html_report(const json& result, const HtmlReportOptions& options) {
  check_imu_result(result, options.source);
  std::vector<std::string> problems;
  report::Page page(&problems);
  for (const ImuSection& s : imu_page_sections(result))
    page.section(s.name, s.id, s.title, [&](std::string& html) { s.render(result, page, html); });
  // The check above should leave no section that cannot be drawn; one that could not is refused as a whole.
  if (!problems.empty())
    throw Error(fmt::format("{}{} The report was not written.",
                            options.source.empty() ? "" : options.source + ": ", problems.front()));
  report::PageHeader header;
  header.title = !options.title.empty()          ? options.title
                 : result_kind(result) == "plan" ? "gyrocal IMU plan report: the predicted calibration"
                                                 : "gyrocal IMU calibration report";
  header.source = options.source;
  header.created = options.created;
  return page.html(header);
}

std::vector<std::string> imu_report_sections(const json& result) {
  std::vector<std::string> names;
  if (!result.is_object() || !result.contains("channels") || !result.at("channels").is_object()) return names;
  for (const ImuSection& s : imu_page_sections(result)) names.push_back(s.name);
  return names;
}

}  // namespace gyrocal
