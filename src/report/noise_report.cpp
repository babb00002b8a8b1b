// The report of a noise characterisation (noise_report.hpp, docs/noise.md): its own table of sections drawn
// on the report's page (page.hpp), from the JSON of `gyrocal noise --json`.
#include "gyrocal/report/noise_report.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "charts.hpp"
#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/noise_terms.hpp"
#include "html_writing.hpp"
#include "page.hpp"
#include "sections.hpp"

namespace gyrocal {
namespace report {
namespace {

/// How a term appears in the report, by NoiseTerm: the formula of its line and its colour (its key, name and
/// unit are the sensor's: sensor_noise_term).
struct TermLook {
  NoiseTerm term;
  const char* line;  // the line's label: its Allan deviation (physics.md section 13)
  const char* colour;
};
constexpr TermLook kTermLooks[] = {
    {NoiseTerm::AngleQuantization,
     "\xE2\x88\x9A"
     "3 Q/\xCF\x84",
     "#76b7b2"},
    {NoiseTerm::AngleRandomWalk, "N/\xE2\x88\x9A\xCF\x84", "#4e79a7"},
    {NoiseTerm::BiasInstability, "0.664 B", "#59a14f"},
    {NoiseTerm::RateRandomWalk, "K \xE2\x88\x9A(\xCF\x84/3)", "#f28e2b"},
    {NoiseTerm::RateRamp,
     "R \xCF\x84/\xE2\x88\x9A"
     "2",
     "#b07aa1"},
};

/// The sensor whose noise the result holds: its "sensor" (a result without one is a gyro's).
SensorKind sensor_of(const json& noise) {
  const json* s = find(noise, "sensor");
  if (s != nullptr && s->is_string()) {
    if (const std::optional<SensorKind> kind = parse_sensor_kind(s->get<std::string>())) return *kind;
  }
  return SensorKind::kGyro;
}

/// The unit of the Allan deviation as the page writes it: deg/h, or \xC2\xB5g for an accelerometer's.
std::string deviation_unit(const json& noise) {
  return sensor_of(noise) == SensorKind::kAccelerometer ? "\xC2\xB5g" : "deg/h";
}

struct AllanPoint {
  double tau_s = 0.0, adev = 0.0;
  std::optional<double> low, high;
};

std::vector<AllanPoint> allan_points(const json& noise) {
  const json& a = member(noise, "allan", "the result");
  expect(a, json::value_t::array, "allan");
  check_table_cells(a.size(), 7, "allan");
  std::vector<AllanPoint> points;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const std::string where = fmt::format("allan[{}]", k);
    expect(a[k], json::value_t::object, where);
    const auto tau = number(a[k], "tau_s", where), adev = number(a[k], "adev", where);
    if (!tau || !adev || *tau <= 0 || *adev <= 0)
      throw Error(fmt::format("{} needs a positive tau_s and adev", where));
    points.push_back({*tau, *adev, number(a[k], "adev_low", where), number(a[k], "adev_high", where)});
  }
  return points;
}

struct FittedTerm {
  const TermLook* look;
  SensorNoiseTerm name;
  std::string key;
  std::optional<double> value, std;
};

/// The fitted terms of the result that gyrocal knows, in the order of kTermLooks; unknown keys in `other`.
std::vector<FittedTerm> fitted_terms(const json& noise, std::vector<std::string>* other = nullptr) {
  const json& t = member(noise, "terms", "the result");
  expect(t, json::value_t::object, "terms");
  const SensorKind sensor = sensor_of(noise);
  std::vector<FittedTerm> out;
  for (const TermLook& look : kTermLooks) {
    const SensorNoiseTerm name = sensor_noise_term(sensor, look.term);
    const std::string key(name.key);
    const json* e = find(t, key);
    if (e == nullptr) continue;
    expect(*e, json::value_t::object, "terms." + key);
    out.push_back({&look, name, key, number(*e, "value", "terms." + key), number(*e, "std", "terms." + key)});
  }
  if (other)
    for (const auto& [key, v] : t.items())
      if (!sensor_noise_term_from_key(sensor, key)) other->push_back(key);
  return out;
}

void summary(const json& noise, Page&, std::string& out) {
  std::vector<std::vector<Cell>> rows;
  if (const json* r = find(noise, "record")) rows.push_back({text_cell("record"), text_cell(value_text(*r))});
  const auto fs = number(noise, "sample_rate_hz", "the result");
  const auto n = number(noise, "samples", "the result");
  rows.push_back({text_cell("sample rate, Hz"), num_cell(num(fs))});
  rows.push_back({text_cell("samples"), num_cell(num(n, 15))});
  if (fs && n && *fs > 0) rows.push_back({text_cell("duration, s"), num_cell(num(*n / *fs))});
  if (const auto chi2 = number(noise, "chi2_per_dof", "the result"))
    rows.push_back(
        {text_cell("misfit of the fit, \xCF\x87\xC2\xB2 per degree of freedom (about 1 when it fits)"),
         num_cell(num(chi2, 3))});
  out += table({"", "value"}, rows, "compact");
}

void allan(const json& noise, Page& page, std::string& out) {
  const std::vector<AllanPoint> points = allan_points(noise);
  const json& a = noise["allan"];
  LogLogChart chart;
  chart.points = json::array();
  chart.low = json::array();
  chart.high = json::array();
  chart.tips = json::array();
  chart.points_label = "Allan deviation";
  chart.bars_label = "68.3 % confidence";
  chart.xlabel = "averaging time \xCF\x84, s";
  const std::string unit = deviation_unit(noise);
  chart.ylabel = "Allan deviation \xCF\x83(\xCF\x84), " + unit;
  std::vector<std::vector<Cell>> rows;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const AllanPoint& p = points[k];
    chart.points.push_back({{"x", p.tau_s}, {"y", p.adev}});
    chart.low.push_back(opt_json(p.low));
    chart.high.push_back(opt_json(p.high));
    chart.tips.push_back(fmt::format("\xCF\x84 = {} s: \xCF\x83 = {} {} (68.3 %: {} \xE2\x80\x93 {})",
                                     num(p.tau_s, 4), num(p.adev, 4), unit, num(p.low, 3), num(p.high, 3)));
    const std::string where = fmt::format("allan[{}]", k);
    rows.push_back({num_cell(num(p.tau_s)), num_cell(num(p.adev, 4)), num_cell(num(p.low, 4)),
                    num_cell(num(p.high, 4)), num_cell(num(number(a[k], "clusters", where), 15)),
                    num_cell(num(number(a[k], "dof", where), 4)),
                    text_cell(string_or(a[k], "dominant", kDash))});
  }
  // The fitted terms' lines over the measured span (straight on log-log axes: two points each) and their sum.
  const json* terms_j = find(noise, "terms");
  if (terms_j != nullptr && terms_j->is_object() && !points.empty()) {
    const double t0 = points.front().tau_s, t1 = points.back().tau_s;
    std::vector<std::pair<NoiseTerm, double>> present;
    for (const FittedTerm& f : fitted_terms(noise)) {
      if (!f.value || *f.value <= 0) continue;
      // The term as characterise_noise states it (a gyro's units on samples in the deviation's unit).
      const double value = *f.value / f.name.per_gyro_value;
      present.emplace_back(f.look->term, value);
      json line = json::array();
      for (const double tau : {t0, t1})
        line.push_back({{"x", tau}, {"y", noise_term_deviation(f.look->term, value, tau)}});
      chart.lines.push_back({{"name", fmt::format("{} ({})", f.look->line, f.name.name)},
                             {"colour", f.look->colour},
                             {"dash", true},
                             {"points", line}});
    }
    if (!present.empty()) {
      json line = json::array();
      constexpr int kSteps = 48;
      for (int i = 0; i <= kSteps; ++i) {
        const double tau = t0 * std::pow(t1 / t0, static_cast<double>(i) / kSteps);
        double variance = 0.0;
        for (const auto& [term, value] : present)
          variance += std::pow(noise_term_deviation(term, value, tau), 2);
        line.push_back({{"x", tau}, {"y", std::sqrt(variance)}});
      }
      chart.lines.push_back({{"name", "fitted model (sum of the terms)"},
                             {"colour", "#1f2328"},
                             {"dash", false},
                             {"points", line}});
    }
  }
  out += page.plot(chart.to_json(), 460,
                   "log-log overlapping Allan deviation with confidence bars and fitted terms");
  out +=
      "<p class=\"note\">Overlapping Allan deviation of the output (IEEE Std 952 annex C) at every octave "
      "\xCF\x84; bars span its 68.3 % confidence interval from the equivalent degrees of freedom of the "
      "noise "
      "that dominates there. Dashed: each fitted term alone; solid: their sum (docs/physics.md section "
      "13).</p>\n";
  out += table({"\xCF\x84, s", "\xCF\x83, " + unit, "68.3 % low", "68.3 % high", "clusters",
                "degrees of freedom", "dominant term"},
               rows, "compact");
}

void terms(const json& noise, Page&, std::string& out) {
  std::vector<std::string> other;
  const std::vector<FittedTerm> fitted = fitted_terms(noise, &other);
  std::vector<std::vector<Cell>> rows;
  for (const FittedTerm& f : fitted) {
    const std::string relative =
        f.value && f.std && *f.value > 0 ? fmt::format("{:.1f} %", 100.0 * *f.std / *f.value) : kDash;
    rows.push_back({text_cell(std::string(f.name.name)), text_cell(f.key), num_cell(value_pm(f.value, f.std)),
                    text_cell(std::string(f.name.unit)), num_cell(relative), text_cell(f.look->line)});
  }
  for (const auto& key : other) {
    const json& e = noise["terms"][key];
    const std::optional<double> value = e.is_object() ? number(e, "value", "terms." + key) : std::nullopt;
    const std::optional<double> std_dev = e.is_object() ? number(e, "std", "terms." + key) : std::nullopt;
    rows.push_back({text_cell(kDash), text_cell(key), num_cell(value_pm(value, std_dev)), text_cell(kDash),
                    text_cell(kDash), text_cell(kDash)});
  }
  if (rows.empty()) {
    out += "<p>The fit kept no term.</p>\n";
    return;
  }
  out += table({"term", "key", "value \xC2\xB1 standard uncertainty", "unit", "relative uncertainty",
                "Allan deviation"},
               rows);
  const bool accelerometer = sensor_of(noise) == SensorKind::kAccelerometer;
  out += fmt::format(
      "<p class=\"note\">The keys are those of <code>[{}.noise]</code> where one exists: "
      "<code>gyrocal noise --toml</code> prints them as a section that <code>plan</code> and "
      "<code>simulate</code> take as they are. A term the fit did not keep is not listed.{}</p>\n",
      accelerometer ? "accelerometer" : "gyro",
      accelerometer ? " <code>quantization_ug</code> is the step of the grid the output's values lie on (its "
                      "resolution), not an Allan term."
                    : "");
}

bool always(const json&) {
  return true;
}
bool has_terms(const json& noise) {
  return find(noise, "terms") != nullptr;
}

/// The table of the sections of a noise report: it drives both the page and its navigation.
const Section kNoiseSections[] = {
    {"summary", "summary", "Record", summary, always},
    {"allan", "allan", "Allan deviation", allan, always},
    {"terms", "terms", "Fitted noise terms", terms, has_terms},
};

}  // namespace

std::span<const Section> noise_sections() {
  return kNoiseSections;
}

}  // namespace report

std::string render_noise_html_report(const nlohmann::json& noise, const HtmlReportOptions& options) {
  if (!noise.is_object())
    throw Error(fmt::format("a noise result must be a JSON object, not a JSON {}", noise.type_name()));
  report::Page page(options.problems);
  report::render_sections(report::kNoiseSections, noise, page);
  report::PageHeader header;
  header.title = options.title.empty() ? "gyrocal noise report" : options.title;
  header.source = options.source;
  header.source_label = "record";
  header.created = options.created;
  return page.html(header);
}

}  // namespace gyrocal
