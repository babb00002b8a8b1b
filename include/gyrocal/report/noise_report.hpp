#pragma once
// The self-contained HTML report of a noise characterisation (`gyrocal noise RECORD --html FILE`,
// docs/noise.md, docs/report.md): the log-log Allan deviation with its 68.3 % confidence bars and the lines
// of the fitted IEEE 952 terms, and a table of the terms with their uncertainties. Same page as the
// calibration report: nothing loaded from outside, Chart.js inlined.
#include <string>

#include <nlohmann/json.hpp>

#include "gyrocal/report/html_report.hpp"

namespace gyrocal {

/// Renders the report of `noise`, the JSON of `gyrocal noise --json` (noise_to_json: record, sample_rate_hz,
/// samples, allan [{tau_s, adev, adev_low, adev_high, clusters, dof, dominant}], terms {key: {value, std}},
/// chi2_per_dof). A part that is malformed shows a sentence saying what is wrong (also put in
/// options.problems). Every string from `noise` is escaped. Throws gyrocal::Error if `noise` is not a JSON
/// object. `options.title` should be set by the caller (its default names a calibration report).
std::string render_noise_html_report(const nlohmann::json& noise, const HtmlReportOptions& options);

}  // namespace gyrocal
