// The text table of an IMU's calibration (gyrocal calibrate of a [sensor] kind = "imu" configuration).
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "tables.hpp"

namespace gyrocal::cli {

std::string imu_result_table(const ImuCalibrationResult& r) {
  std::string out = fmt::format(
      "IMU of {} channels, least squares with compensation full: Ar = {:.4f} g, rank {}/{}, condition "
      "{:.3g}, "
      "{} warning{}\n",
      r.channels.size(), r.g_level, r.rank, r.unknowns, r.condition_number, r.warnings.size(),
      r.warnings.size() == 1 ? "" : "s");
  for (const ImuChannelResult& c : r.channels) {
    out += fmt::format("\nchannel {} ({}): chi2 {:.4g} on {} dof{}\n", c.name, to_string(c.sensor),
                       c.misfit.chi2, c.misfit.dof,
                       c.misfit.scale != 1.0 ? fmt::format(", std x {:.3g}", c.misfit.scale) : std::string());
    out += fmt::format("{:<16} {:>30}  {}\n", "coefficient", "estimate ± std", "unit");
    for (const CoefficientEstimate& e : c.coefficients)
      out += fmt::format("{:<16} {:>30}  {}\n", e.name,
                         e.identifiable ? format_value_std(e.value, e.std) : std::string("not identifiable"),
                         e.unit);
    if (!c.combinations.empty()) out += "combinations the data identify\n";
    for (const NamedEstimate& e : c.combinations)
      out += fmt::format("  {} = {}  {}\n", e.name, format_value_std(e.value, e.std), e.unit);
  }
  if (!r.machine_errors.empty()) {
    out += fmt::format("\nmachine errors estimated ({} Gauss-Newton iterations)\n", r.iterations);
    out += fmt::format("{:<30} {:>30} {:>12}  {}\n", "error", "estimate ± std", "configured", "unit");
    for (const MachineErrorEstimate& e : r.machine_errors) {
      const PrintedUnit shown = printed_unit(e.unit);
      out += fmt::format("{:<30} {:>30} {:>12.6g}  {}\n", e.parameter.label(),
                         format_value_std(e.value * shown.factor, e.std * shown.factor),
                         e.configured * shown.factor, shown.unit);
    }
  }
  if (!r.input_axis_angles.empty()) {
    out += "\nthe triad's geometry: angles between fitted input axes\n";
    out += fmt::format("{:<12} {:>18} {:>30}\n", "channels", "angle (deg)", "from nominal ± std (urad)");
    for (const InputAxisAngle& a : r.input_axis_angles)
      out += fmt::format("{:<12} {:>18.9f} {:>30}\n", a.first + "-" + a.second, a.angle_deg,
                         format_value_std(a.deviation_urad, a.std_urad));
  }
  for (const std::string& w : r.warnings) out += "\nwarning: " + w + "\n";
  for (const ImuChannelResult& c : r.channels)
    for (const std::string& w : c.warnings) out += fmt::format("\nwarning ({}): {}\n", c.name, w);
  return out;
}

std::string imu_sensitivity_table(const ImuSensitivityResult& r) {
  std::string out = fmt::format(
      "IMU error study: each machine error alone, not told to the calibration; an estimate is listed where "
      "its shift exceeds {:g} of its predicted noise std (shift, and in std)\n",
      r.threshold);
  if (!r.not_identifiable.empty()) {
    out += "not identifiable from this plan (no shift stated):";
    for (const std::string& n : r.not_identifiable) out += " " + n;
    out += "\n";
  }
  for (const ImuSensitivityRow& row : r.rows) {
    out += fmt::format("\n{} = {:.6g} {}{}: ", row.term.label(), row.value, row.term.unit,
                       row.typical ? " (typical)" : "");
    if (row.matters.empty()) {
      out += "no estimate moves by that much\n";
      continue;
    }
    out += fmt::format("{} estimate{}\n", row.matters.size(), row.matters.size() == 1 ? "" : "s");
    for (const std::string& name : row.matters) {
      const double shift = row.shift.at(name), sigma = r.noise_std.at(name);
      const PrintedUnit shown = printed_unit(r.units.at(name));
      out += fmt::format("  {:<28} {:>+14.6g} {:<12} {:>+9.3g} std\n", name, shift * shown.factor, shown.unit,
                         shift / sigma);
    }
  }
  return out;
}

}  // namespace gyrocal::cli
