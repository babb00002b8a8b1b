// The report's plot descriptions (charts.hpp): the JSON that report.js reads.
#include "charts.hpp"

namespace gyrocal::report {

using nlohmann::json;

json ErrorBarChart::to_json() const {
  return {{"kind", "errorbar"},
          {"labels", labels},
          {"center", center},
          {"low", low},
          {"high", high},
          {"tips", tips},
          {"center_label", center_label},
          {"band_label", band_label},
          {"xlabel", xlabel},
          {"ylabel", ylabel}};
}

json ScatterChart::to_json() const {
  return {{"kind", "scatter"}, {"series", series}, {"xlabel", xlabel}, {"ylabel", ylabel},
          {"xmin", xmin},      {"xmax", xmax},     {"ymin", ymin},     {"ymax", ymax},
          {"xticks", xticks},  {"yticks", yticks}};
}

json HeatMapChart::to_json() const {
  return {{"kind", "heatmap"}, {"rows", rows},     {"cols", cols},    {"colours", colours},
          {"tips", tips},      {"xlabel", xlabel}, {"ylabel", ylabel}};
}

json HistogramChart::to_json() const {
  return {{"kind", "histogram"}, {"labels", labels}, {"counts", counts}, {"tips", tips},
          {"title", title},      {"xlabel", xlabel}, {"ylabel", ylabel}};
}

json StackedChart::to_json() const {
  return {{"kind", "stacked"}, {"labels", labels}, {"series", series},
          {"xlabel", xlabel},  {"ylabel", ylabel}, {"ymax", ymax}};
}

json LogLogChart::to_json() const {
  return {{"kind", "loglog"},
          {"points", points},
          {"low", low},
          {"high", high},
          {"tips", tips},
          {"points_label", points_label},
          {"bars_label", bars_label},
          {"lines", lines},
          {"xlabel", xlabel},
          {"ylabel", ylabel}};
}

json ControlChart::to_json() const {
  return {{"kind", "control"},
          {"points", points},
          {"low", low},
          {"high", high},
          {"tips", tips},
          {"flagged", flagged},
          {"mean", mean},
          {"limits", limits},
          {"ewma", ewma},
          {"ewma_low", ewma_low},
          {"ewma_high", ewma_high},
          {"ewma_tips", ewma_tips},
          {"ewma_flagged", ewma_flagged},
          {"title", title},
          {"ylabel", ylabel},
          {"mean_label", mean_label}};
}

}  // namespace gyrocal::report
