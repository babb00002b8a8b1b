#include "tables.hpp"

#include <cmath>

#include <fmt/format.h>

namespace gyrocal::cli {
namespace {

std::string value_std(double v, double s) {
  if (!std::isfinite(v)) return "not identifiable";
  if (!std::isfinite(s)) return fmt::format("{:.6f}", v);
  return fmt::format("{:.6f} ± {:.6f}", v, s);
}

}  // namespace

std::string result_table(const CalibrationResult& r) {
  std::string out = r.BriefReport() + "\n\n";
  out += fmt::format("{:<16} {:>30}  {}\n", "coefficient", "estimate ± std", "unit");
  for (std::size_t k = 0; k < kNumCoefficients; ++k)
    out += fmt::format("{:<16} {:>30}  {}\n", kCoefficientNames[k],
                       value_std(r.coefficients[k].value, r.coefficients[k].std), kCoefficientUnits[k]);
  if (!r.combinations.empty()) {
    out += "\nidentifiable combinations\n";
    for (const NamedEstimate& c : r.combinations)
      out += fmt::format("{:<16} {:>30}  {}\n", c.name, value_std(c.value, c.std), c.unit);
  }
  if (!r.alternatives.empty()) {
    out += "\nclosed form's second expressions\n";
    for (const NamedEstimate& c : r.alternatives)
      out += fmt::format("{:<16} {:>30}  {}\n", c.name, value_std(c.value, c.std), c.unit);
  }
  if (!r.warnings.empty()) {
    out += "\nwarnings\n";
    for (const std::string& w : r.warnings) out += "- " + w + "\n";
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
    return std::isfinite(e.std) && e.std > 0 ? fmt::format("{:.5f} ± {:.5f}", e.value, e.std)
                                             : fmt::format("{:.6f}", e.value);
  };
  for (std::size_t k = 0; k < kNumCoefficients; ++k) {
    out += fmt::format("{:<16}", fmt::format("{} [{}]", kCoefficientNames[k], kCoefficientUnits[k]));
    if (truth) out += fmt::format("{:>10.4f}", truth->values[k]);
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
        for (std::size_t k = 0; k < first.coefficients.size() && k < kNumCoefficients; ++k)
          v += first.coefficients[k] * truth->values[k];
        out += fmt::format("{:>10.4f}", v);
      }
      for (const CalibrationResult& r : results) {
        std::string cellv = "—";
        for (const NamedEstimate& e : r.combinations)
          if (e.name == name)
            cellv = std::isfinite(e.std) && e.std > 0 ? fmt::format("{:.5f} ± {:.5f}", e.value, e.std)
                                                      : fmt::format("{:.6f}", e.value);
        out += fmt::format("{:>{}}", cellv, kWidth);
      }
      out += "\n";
    }
  }
  return out;
}

}  // namespace gyrocal::cli
