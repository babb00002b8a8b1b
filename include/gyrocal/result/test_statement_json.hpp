#pragma once
// What a calibration's report states beyond the estimates (docs/report.md, "A report a lab can sign"): the
// unit under test, the truth a simulated record carries, the g-levels and the test sequence with its
// duration, and an accelerometer's input at each reduced position (its linearity plot). Written into the
// result file by `gyrocal calibrate --json` and the accelerometer demo; the report reads them.
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/reduce/reducer.hpp"

namespace gyrocal {

/// The record's metadata keys that state the unit under test (`# unit = SN-1`), each with the [unit] key it
/// stands for: unit and serial (serial), model, operator, date, temperature_c.
inline constexpr std::string_view kUnitMetadataKeys[] = {"unit",     "serial", "model",
                                                         "operator", "date",   "temperature_c"};

/// Adds to the result `j` (calibration_to_json's, with its `coefficients` and `warnings`):
/// - `unit_under_test` {serial, model, operator, date, temperature_c, notes, from: {key: where}}: the
///   configuration's [unit] keys, the record's metadata (kUnitMetadataKeys) for those it leaves out; absent
///   when neither states anything. A [unit] serial that differs from the record's `unit`/`serial` adds a
///   warning (a configuration written for another unit);
/// - `truth` {name: value}: the record's `truth_<name>` metadata (a simulated record) for each coefficient
///   of `j`; absent when it has none;
/// - `test_sequence` {radius_m, gravity_m_s2, g_levels: [{rate_rad_s, rpm, centripetal_g, magnitude_g}],
///   planned_duration_s, steps: [{kind, rate_rad_s, centripetal_g, beta_deg, positions, start_s, end_s}]}:
///   the planned test (plan/timeline.hpp) as its operator runs it, in time order;
/// - for an accelerometer, `position_inputs` [{index, a_i_g, a_p_g, a_o_g}]: the nominal specific force in
///   the sensor's axes at each reduced position of `positions` (model/nominal.hpp), in g.
/// `metadata` may be null (no record read). Returns the warnings it added to j["warnings"], for the caller
/// to print.
std::vector<std::string> add_test_statement(nlohmann::ordered_json& j, const Scenario& s,
                                            const RecordMetadata* metadata,
                                            const std::vector<ReducedPosition>& positions,
                                            std::string_view record_name);

}  // namespace gyrocal
