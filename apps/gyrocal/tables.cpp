#include "tables.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>

#include <fmt/format.h>

namespace gyrocal::cli {
namespace {

std::string value_std(double v, double s) {
  if (!std::isfinite(v)) return "not identifiable";
  return format_value_std(v, s);
}

}  // namespace

PrintedUnit printed_unit(std::string_view unit) {
  // A length (a radius, a runout, a lever arm, a stretch per (rad/s)^2) is measured to microns: printed in
  // them, "0.00002984 +- 0.00000061 m" being unreadable. The JSON keeps the SI unit (docs/contract.md).
  if (unit == "m" || unit.starts_with("m/")) return {1e6, "um" + std::string(unit.substr(1))};
  return {1.0, std::string(unit)};
}

std::string format_value_std(double value, double std_dev) {
  if (!std::isfinite(value)) return fmt::format("{}", value);
  if (!(std::isfinite(std_dev) && std_dev > 0.0)) return fmt::format("{:.6g}", value);
  // The standard deviation to two significant digits, the value to the same last digit.
  const int first = static_cast<int>(std::floor(std::log10(std_dev)));  // the std's first digit
  const int last = first - 1;                                           // the last digit shown
  const int top = static_cast<int>(std::floor(std::log10(std::max(std::abs(value), std_dev))));
  if (top - last > 10)  // an uncertainty far below the value: the value to 10 digits, the std apart
    return fmt::format("{:.10g} ± {:.2g}", value, std_dev);
  if (top < 6 && last >= -12) {  // fixed point
    if (last > 0) {              // digits left of the point: rounded to the std's second digit
      const double unit = std::pow(10.0, last);
      return fmt::format("{:.0f} ± {:.0f}", std::round(value / unit) * unit,
                         std::round(std_dev / unit) * unit);
    }
    return fmt::format("{:.{}f} ± {:.{}f}", value, -last, std_dev, -last);
  }
  // Scientific, both in the exponent of the larger.
  const double scale = std::pow(10.0, top);
  return fmt::format("({:.{}f} ± {:.{}f})e{}", value / scale, top - last, std_dev / scale, top - last, top);
}

std::string result_table(const CalibrationResult& r) {
  std::string out = r.BriefReport() + "\n\n";
  out += fmt::format("{:<16} {:>30}  {}\n", "coefficient", "estimate ± std", "unit");
  // The sensor's table (the gyro's dF .. dOS, an accelerometer's K0 .. delta_o); the gyro's rate errors of
  // drift+rate under their own heading (docs/physics.md section 15).
  const bool rate_errors = r.sensor == SensorKind::kGyro && r.gyro_model == GyroModel::kDriftRate;
  for (std::size_t k = 0; k < r.coefficients.size(); ++k) {
    const CoefficientEstimate& c = r.coefficients[k];
    if (rate_errors && k == kNumGyroCoefficients) out += "\nrate errors (gyro model drift+rate)\n";
    const int width = rate_errors && k >= kNumGyroCoefficients ? 34 : 16;
    out += fmt::format("{:<{}} {:>30}  {}\n", c.name, width, value_std(c.identifiable ? c.value : NAN, c.std),
                       c.unit);
  }
  if (!r.combinations.empty()) {
    out += "\nidentifiable combinations\n";
    for (const NamedEstimate& c : r.combinations)
      out += fmt::format("{:<16} {:>30}  {}\n", c.name, value_std(c.value, c.std), c.unit);
  }
  if (!r.machine_errors.empty()) {
    // The self-calibration: each estimate beside its configured value, and its correlation with the
    // coefficients it trades against (dI, dOS) or any other beyond 0.5.
    out += fmt::format("\nmachine errors estimated ({} Gauss-Newton iterations)\n", r.iterations);
    out += fmt::format("{:<30} {:>30} {:>12}  {:<12} {}\n", "error", "estimate ± std", "configured", "unit",
                       "correlations");
    for (const MachineErrorEstimate& e : r.machine_errors) {
      std::string correlations;
      for (const auto& [name, rho] : e.correlations)
        if (std::isfinite(rho) && (name == "dI" || name == "dOS" || std::abs(rho) > 0.5))
          correlations += fmt::format("{}{} {:+.2f}", correlations.empty() ? "" : ", ", name, rho);
      const PrintedUnit shown = printed_unit(e.unit);
      out += fmt::format("{:<30} {:>30} {:>12.6g}  {:<12} {}\n", e.parameter.label(),
                         e.identifiable ? value_std(e.value * shown.factor, e.std * shown.factor)
                                        : std::string("not identifiable"),
                         e.configured * shown.factor, shown.unit, correlations);
    }
  }
  if (!r.alternatives.empty()) {
    out += "\nclosed form's second expressions\n";
    for (const NamedEstimate& c : r.alternatives)
      out += fmt::format("{:<16} {:>30}  {}\n", c.name, value_std(c.value, c.std), c.unit);
  }
  const DataQuality& q = r.data_quality;
  if (q.rows_read > 0) {
    out +=
        fmt::format("\ndata quality: {} rows read, {} used, {} outliers, {} gaps, {} encoder glitch rows\n",
                    q.rows_read, q.rows_used, q.outliers, q.gaps, q.encoder_glitch_rows);
    out += fmt::format("{:>9} {:>9} {:>9} {:>11} {:>7} {:>7} {:>8} {:>7} {:>8} {:>5}  {}\n", "rate", "beta",
                       "start_s", "rows used", "settle", "beyond", "glitches", "leaving", "outliers", "gaps",
                       "ended");
    for (const DataQuality::Dwell& d : q.dwells)
      out += fmt::format("{:>9.4g} {:>9.3f} {:>9.3f} {:>5}/{:<5} {:>7} {:>7} {:>8} {:>7} {:>8} {:>5}  {}\n",
                         d.rate_rad_s, d.beta_deg, d.start_s, d.rows_used, d.rows, d.settle_rows,
                         d.beyond_planned_rows, d.encoder_glitch_rows, d.before_leaving_rows, d.outliers,
                         d.gaps, d.ended);
    // The counter platform turning with the main axis stopped is a static set's indexing move between its
    // holds: counted in one line, not listed one by one (docs/calibration.md).
    constexpr std::string_view kIndexing = "the main axis stands still while the counter platform turns";
    std::size_t indexing = 0;
    double first = 0.0, last = 0.0;
    for (const DataQuality::Rejected& x : q.rejected) {
      if (std::string_view(x.reason).starts_with(kIndexing)) {
        if (indexing++ == 0) first = x.start_s;
        last = x.end_s;
        continue;
      }
      out += fmt::format("- no dwell from the steady run at t = {:.3f} to {:.3f} s: {}\n", x.start_s, x.end_s,
                         x.reason);
    }
    if (indexing > 0)
      out += fmt::format(
          "- {} steady run{} between t = {:.3f} and {:.3f} s where the main axis stands still while the "
          "counter "
          "platform turns (a static set's indexing moves between its holds) gave no dwell, as planned\n",
          indexing, indexing == 1 ? "" : "s", first, last);
  }
  if (!r.warnings.empty()) {
    out += "\nwarnings\n";
    for (const std::string& w : r.warnings) out += "- " + w + "\n";
  }
  return out;
}

std::string sensor_comparison_table(const std::vector<std::string>& labels,
                                    const std::vector<CalibrationResult>& results,
                                    std::span<const SensorParameter> parameters,
                                    std::span<const double> truth) {
  constexpr int kWidth = 30;
  std::string out = fmt::format("{:<18}{:>12}", "", "truth");
  for (const std::string& l : labels) out += fmt::format("{:>{}}", l, kWidth);
  out += "\n";
  for (std::size_t k = 0; k < parameters.size(); ++k) {
    out += fmt::format("{:<18}{:>12.6g}", fmt::format("{} [{}]", parameters[k].name, parameters[k].unit),
                       k < truth.size() ? truth[k] : NAN);
    for (const CalibrationResult& r : results) {
      std::string cell = "—";
      for (const CoefficientEstimate& c : r.coefficients)
        if (c.name == parameters[k].name && c.identifiable) cell = format_value_std(c.value, c.std);
      out += fmt::format("{:>{}}", cell, kWidth);
    }
    out += "\n";
  }
  return out;
}

std::string comparison_table(const std::vector<std::string>& labels,
                             const std::vector<CalibrationResult>& results, const DriftCoefficients* truth) {
  constexpr int kWidth = 24;
  std::string out = fmt::format("{:<16}", "");
  if (truth) out += fmt::format("{:>10}", "truth");
  for (const std::string& l : labels) out += fmt::format("{:>{}}", l, kWidth);
  out += "\n";
  const auto cell = [](const CalibrationResult& r, std::size_t k) -> std::string {
    const CoefficientEstimate& e = r.coefficients[k];
    if (!e.identifiable) return "—";
    return format_value_std(e.value, e.std);
  };
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    out += fmt::format("{:<16}", fmt::format("{} [{}]", kCoefficientNames[k], kCoefficientUnits[k]));
    if (truth) out += fmt::format("{:>10.6g}", truth->values[k]);
    for (const CalibrationResult& r : results) out += fmt::format("{:>{}}", cell(r, k), kWidth);
    out += "\n";
  }
  // The identifiable combinations where coefficients are not.
  if (!results.empty()) {
    for (std::size_t c = 0; c < results.front().combinations.size(); ++c) {
      const NamedEstimate& first = results.front().combinations[c];
      const std::string& name = first.name;
      out += fmt::format("{:<16}", name);
      if (truth) {
        // The truth of the combination: its reported coefficients applied to the true coefficients.
        double v = 0.0;
        for (std::size_t k = 0; k < first.coefficients.size() && k < kNumGyroCoefficients; ++k)
          v += first.coefficients[k] * truth->values[k];
        out += fmt::format("{:>10.6g}", v);
      }
      for (const CalibrationResult& r : results) {
        std::string cellv = "—";
        for (const NamedEstimate& e : r.combinations)
          if (e.name == name) cellv = format_value_std(e.value, e.std);
        out += fmt::format("{:>{}}", cellv, kWidth);
      }
      out += "\n";
    }
  }
  return out;
}

}  // namespace gyrocal::cli
