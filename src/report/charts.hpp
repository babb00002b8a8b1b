#pragma once
// The report's plot descriptions (docs/report.md), private to src/report: one struct per kind of plot, turned
// into the JSON that the page's script (report.js, `builders`) hands to Chart.js. This file and report.js are
// the two sides of one contract: a field added here is read there under the same name.
#include <string>

#include <nlohmann/json.hpp>

namespace gyrocal::report {

/// Values with an error bar per category (kind "errorbar"): the bar is a floating bar [low, high], the value
/// a point. labels, center, low, high and tips have one entry per category (null = no value).
struct ErrorBarChart {
  nlohmann::json labels, center, low, high, tips;
  std::string center_label, band_label, xlabel, ylabel;
  nlohmann::json to_json() const;
};

/// Points in the plane per series (kind "scatter"); series: [{name, colour, points: [{x, y}], tips: [...]}].
/// Axis limits and ticks are optional (null = automatic).
struct ScatterChart {
  nlohmann::json series;
  std::string xlabel, ylabel;
  nlohmann::json xmin, xmax, ymin, ymax, xticks, yticks;
  nlohmann::json to_json() const;
};

/// A heat map (kind "heatmap"): colours[i][j] and tips[i][j] for row i, column j.
struct HeatMapChart {
  nlohmann::json rows, cols, colours, tips;
  std::string xlabel, ylabel;
  nlohmann::json to_json() const;
};

/// A histogram (kind "histogram"): one bar per bin, labels its centre, tips its interval.
struct HistogramChart {
  nlohmann::json labels, counts, tips;
  std::string title, xlabel, ylabel;
  nlohmann::json to_json() const;
};

/// Stacked bars (kind "stacked"): series [{name, values, colour}], one value per label; y from 0 to ymax.
struct StackedChart {
  nlohmann::json labels, series;
  std::string xlabel, ylabel;
  double ymax = 100.0;
  nlohmann::json to_json() const;
};

/// Both axes logarithmic (kind "loglog"): measured points [{x, y}] with error bars [low, high] (one per
/// point, null = none) and their tips, and lines [{name, colour, dash, points: [{x, y}]}] drawn through their
/// points.
struct LogLogChart {
  nlohmann::json points, low, high, tips;
  std::string points_label, bars_label;
  nlohmann::json lines = nlohmann::json::array();
  std::string xlabel, ylabel;
  nlohmann::json to_json() const;
};

/// A control chart (kind "control"): each run's value (points [{x, y}], x its date in days since 1970-01-01
/// UTC, which the page writes as a date) with its error bar [low, high] and its tip, marked where `flagged`
/// (one boolean per point); the mean as a line (null = none); the Shewhart limits [low, high] as two lines
/// (null = none); the EWMA per run (ewma [{x, y}], empty = none) with its limits per run (ewma_low,
/// ewma_high), its tips, and marked where `ewma_flagged`.
struct ControlChart {
  nlohmann::json points = nlohmann::json::array(), low = nlohmann::json::array(),
                 high = nlohmann::json::array(), tips = nlohmann::json::array(),
                 flagged = nlohmann::json::array();
  nlohmann::json mean, limits;
  nlohmann::json ewma = nlohmann::json::array(), ewma_low = nlohmann::json::array(),
                 ewma_high = nlohmann::json::array(), ewma_tips = nlohmann::json::array(),
                 ewma_flagged = nlohmann::json::array();
  std::string title, ylabel, mean_label;
  nlohmann::json to_json() const;
};

}  // namespace gyrocal::report
