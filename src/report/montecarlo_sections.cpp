// A Monte Carlo run's distributions and variance budget, as a section of a calibration result's report and
// as the page of a Monte Carlo run (`gyrocal montecarlo --json`), with that page's table of sections
// (docs/report.md).
#include "section_renderers.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <unordered_map>
#include <utility>

#include <fmt/format.h>

#include "charts.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/report/html_report.hpp"
#include "html_writing.hpp"

namespace gyrocal::report::section {
namespace {

/// The distributions and budget of a Monte Carlo run `m` (montecarlo_to_json); `result` is the whole result
/// it is part of (or `m` itself), for the estimates' units.
void montecarlo_run(const json& m, const json& result, Page& page, std::string& out) {
  expect(m, json::value_t::object, "montecarlo");
  // A run on its own page says its trials in its settings (montecarlo_settings).
  if (const auto trials = number(m, "trials", "montecarlo"); trials && &m != &result)
    out += fmt::format("<p>{} trials.</p>\n", esc(num(trials, 12)));
  if (const json* c = find(m, "coefficients")) {
    expect(*c, json::value_t::object, "montecarlo.coefficients");
    check_table_cells(c->size(), 6, "montecarlo.coefficients");
    // The histograms' bins, each a bar with its label and tooltip: as many cells as a table of a row per
    // histogram and a column per bin of the largest.
    std::size_t histograms = 0, most_bins = 0;
    for (const auto& [name, e] : c->items())
      if (const json* h = find(e, "histogram"))
        if (const json* counts = find(*h, "counts"); counts && counts->is_array()) {
          ++histograms;
          most_bins = std::max(most_bins, counts->size());
        }
    check_table_cells(histograms, most_bins, "montecarlo.coefficients' histograms");
    std::vector<std::vector<Cell>> rows;
    std::string grid;
    for (const auto& name : ordered_keys(*c)) {
      const std::string where = "montecarlo.coefficients." + name;
      const json& e = (*c)[name];
      expect(e, json::value_t::object, where);
      const auto mean = number(e, "mean", where), std_dev = number(e, "std", where);
      // The entry's own unit (a rate error's ppm or arcsec), else the result's coefficients'.
      std::string unit = string_or(e, "unit");
      if (unit.empty()) unit = unit_of(result, name);
      rows.push_back({text_cell(name), num_cell(num(mean, 4)), num_cell(num(std_dev, 3)),
                      num_cell(num(number(e, "predicted_std", where), 3)),
                      num_cell(num(number(e, "z_std", where), 3)), text_cell(unit)});
      const json* h = find(e, "histogram");
      if (h == nullptr) continue;
      const json& edges = member(*h, "edges", where + ".histogram");
      const json& counts = member(*h, "counts", where + ".histogram");
      expect(edges, json::value_t::array, where + ".histogram.edges");
      expect(counts, json::value_t::array, where + ".histogram.counts");
      if (edges.size() != counts.size() + 1)
        throw Error(fmt::format("{}.histogram has {} edges for {} counts (edges must be one more)", where,
                                edges.size(), counts.size()));
      json labels = json::array(), values = json::array(), tips = json::array();
      for (std::size_t b = 0; b < counts.size(); ++b) {
        const auto lo = number(edges[b], where + ".histogram.edges[]"),
                   hi = number(edges[b + 1], where + ".histogram.edges[]");
        const auto n = number(counts[b], where + ".histogram.counts[]");
        labels.push_back(lo && hi ? num(0.5 * (*lo + *hi), 2) : kDash);
        values.push_back(opt_json(n));
        tips.push_back(fmt::format("[{}, {})", num(lo, 4), num(hi, 4)));
      }
      const HistogramChart chart{
          .labels = labels,
          .counts = values,
          .tips = tips,
          .title = fmt::format("{}: mean {}, std {}", name, num(mean, 3), num(std_dev, 2)),
          .xlabel = unit.empty() ? name : name + ", " + unit,
          .ylabel = "trials"};
      grid += page.plot(chart.to_json(), 220, "histogram of " + name + " over the Monte Carlo trials",
                        "plot cell");
    }
    out += table({"estimate", "mean error (estimate \xE2\x88\x92 truth)", "standard deviation of the error",
                  "predicted std", "z std (error / stated \xCF\x83)", "unit"},
                 rows, "compact");
    out += not_identifiable_notes(find(m, "not_identifiable"), "montecarlo.not_identifiable");
    if (!grid.empty()) out += "<h3>Distributions</h3>\n<div class=\"grid\">\n" + grid + "</div>\n";
  }
  if (const json* b = find(m, "budget")) {
    expect(*b, json::value_t::object, "montecarlo.budget");
    const std::vector<std::string> coefs = ordered_keys(*b);
    std::vector<std::string> sources;
    std::set<std::string> source_set;
    for (const auto& name : coefs) {
      expect((*b)[name], json::value_t::object, "montecarlo.budget." + name);
      for (const auto& [source, v] : (*b)[name].items())
        if (source_set.insert(source).second) sources.push_back(source);
    }
    // A row per estimate: its name, a share per source and the total (the stacked bars hold as many).
    check_table_cells(coefs.size(), sources.size() + 2, "montecarlo.budget");
    // Noise first, then the machine errors as the result names them.
    std::stable_partition(sources.begin(), sources.end(), [](const std::string& s) { return s == "noise"; });
    json series = json::array();
    std::vector<std::vector<Cell>> rows;
    for (const auto& name : coefs) rows.push_back({text_cell(name)});
    for (std::size_t i = 0; i < sources.size(); ++i) {
      json values = json::array();
      for (std::size_t k = 0; k < coefs.size(); ++k) {
        const auto share = number((*b)[coefs[k]], sources[i], "montecarlo.budget." + coefs[k]);
        values.push_back(share ? json(100.0 * *share) : json(nullptr));
        rows[k].push_back(num_cell(share ? fmt::format("{:.1f}", 100.0 * *share) : kDash));
      }
      series.push_back({{"name", sources[i]}, {"values", values}, {"colour", palette(i)}});
    }
    double largest_total = 0.0;
    for (std::size_t k = 0; k < coefs.size(); ++k) {
      double total = 0.0;
      for (const auto& source : sources)
        total += number((*b)[coefs[k]], source, "montecarlo.budget." + coefs[k]).value_or(0.0);
      rows[k].push_back(num_cell(fmt::format("{:.1f}", 100.0 * total)));
      largest_total = std::max(largest_total, 100.0 * total);
    }
    out +=
        "<h3>Variance budget</h3>\n<p class=\"note\">The share of each source in each estimate's variance, "
        "in percent.</p>\n";
    const StackedChart chart{.labels = coefs,
                             .series = series,
                             .xlabel = "estimate",
                             .ylabel = "share of variance, %",
                             .ymax = largest_total <= 101.0 ? 100.0 : std::ceil(largest_total)};
    out += page.plot(chart.to_json(), 360,
                     "stacked bars: share of each error source in each estimate's variance");
    std::vector<std::string> header = {"estimate"};
    header.insert(header.end(), sources.begin(), sources.end());
    header.push_back("total");
    out += table(header, rows);
  }
}

}  // namespace

void montecarlo(const json& result, Page& page, std::string& out) {
  montecarlo_run(member(result, "montecarlo", "the result"), result, page, out);
}

namespace {

// --- the page of a Monte Carlo run (`gyrocal montecarlo --json`) -------------------------------------

void montecarlo_settings(const json& m, Page&, std::string& out) {
  std::vector<std::vector<Cell>> rows;
  const auto item = [&](std::string_view key, std::string_view label) {
    if (const json* j = find(m, key); j && !j->is_null())
      rows.push_back({text_cell(label),
                      j->is_number() ? num_cell(num(number(*j, key), 15)) : text_cell(scalar_text(*j))});
  };
  item("trials", "trials");
  item("mode", "mode (fast: linearised; samples: each trial simulated and reduced)");
  item("seed", "random seed");
  item("method", "method");
  item("compensation", "compensation");
  item("gyro_model", "gyro model");
  out += table({"", ""}, rows, "compact");
  out +=
      "<p class=\"note\">Each trial draws the machine errors of <code>[uncertainty]</code> about their "
      "configured values and the noise, and calibrates with the configured values: the spread of the error "
      "(estimate \xE2\x88\x92 truth) is the uncertainty the machine's imperfect knowledge adds.</p>\n";
  if (const json* sources = find(m, "sources")) {
    expect(*sources, json::value_t::array, "sources");
    out += "<h3>Error sources</h3>\n";
    out += generic_table(*sources, {"name", "std", "unit"}, "sources");
  }
}

void montecarlo_body(const json& m, Page& page, std::string& out) {
  montecarlo_run(m, m, page, out);
}

const Section kMonteCarloSections[] = {
    {"provenance", "provenance", "Provenance", provenance, has_provenance},
    {"run", "run", "The run", montecarlo_settings,
     [](const json& m) { return has(m, "trials") || has(m, "sources"); }},
    {"montecarlo", "montecarlo", "Distributions and variance budget", montecarlo_body,
     [](const json& m) { return has(m, "coefficients") || has(m, "budget"); }},
};

}  // namespace
}  // namespace gyrocal::report::section

namespace gyrocal::report {

std::span<const Section> montecarlo_sections() {
  return section::kMonteCarloSections;
}

}  // namespace gyrocal::report
