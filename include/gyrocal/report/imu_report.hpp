#pragma once
// The HTML report of a whole IMU's calibration or plan (docs/report.md, "An IMU's result"; docs/imu.md): the
// same self-contained page as a lone sensor's, drawn from the IMU result JSON (imu_calibration_to_json). A
// summary of the joint fit, the shared machine errors, the triad's geometry, then one section per channel
// with the lone sensor's own tables and plots. Unlike a lone result's page, which shows a sentence in place
// of a malformed section, an IMU result is checked whole before anything is drawn: a missing or malformed
// key is refused, named, and nothing is written.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gyrocal/report/html_report.hpp"

namespace gyrocal {

/// True when `result` is an IMU's calibration or plan result (result_kind, so not a unit's history): a JSON
/// object whose `sensor` is "imu", or which keys its estimates by channel (`channels`), whatever its `sensor`
/// (check_imu_result then refuses a `sensor` other than "imu").
bool is_imu_result(const nlohmann::json& result);

/// Checks an IMU result before its page is drawn (docs/contract.md, "IMUs"): `channels` (1 to
/// limits::kMaxImuChannels, each named by 1 to 32 letters, digits and `_ - .`, its `sensor` "gyro" or
/// "accelerometer", its `coefficients` {name: {value, std, unit, identifiable, reason?}}, `misfit`
/// {tested, ...}, `warnings`), `machine_errors`, `input_axis_angles` (each pair naming two channels),
/// `positions` (each naming its channel), `rank`, `unknowns`, `condition_number`, `iterations`, `warnings`,
/// and the types of the optional keys it holds (`data_quality`, `truth`, `truth_machine`, `method`, ...).
/// Throws gyrocal::Error naming `source` (when not empty) and the key's path
/// (channels.gx.coefficients.dF.std) for the first key that is missing or of the wrong type. Numbers may be
/// null (NaN, not stated) where the result writes null.
void check_imu_result(const nlohmann::json& result, const std::string& source = "");

/// The page of an IMU result (check_imu_result first): a summary (the channels, the joint fit's rank,
/// condition number and iterations, the data quality's counts with increments_dropped, its warnings), the
/// shared machine errors (estimate ± σ beside the configured value, lengths in µm), the triad's geometry
/// (each pair's angle, its deviation from nominal ± σ in µrad), one section per channel in the result's
/// order (its coefficients with identifiability and reason and, in a simulated result, its truth; its misfit
/// verdict and warnings; its reduced positions with their residuals plotted), then the plan, the data quality
/// and the provenance. Throws gyrocal::Error as check_imu_result does, and when a section cannot be drawn,
/// naming it: no page is returned half drawn.
std::string render_imu_html_report(const nlohmann::json& result, const HtmlReportOptions& options = {});

/// The names of the sections the page of the IMU result `result` draws, in page order ("summary",
/// "machine_errors", "geometry", "channel gx", ..., "plan", "data_quality", "provenance").
std::vector<std::string> imu_report_sections(const nlohmann::json& result);

}  // namespace gyrocal
