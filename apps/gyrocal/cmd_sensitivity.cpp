// gyrocal sensitivity: the seed's error study (docs/physics.md section 10, docs/contract.md).

#include <algorithm>
#include <cmath>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/analysis/sensitivity.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/identify/scenario_options.hpp"
#include "gyrocal/identify/unknowns.hpp"
#include "gyrocal/result/coefficient_order.hpp"
#include "gyrocal/result/sensitivity_json.hpp"
#include "tables.hpp"

namespace gyrocal::cli {
namespace {

constexpr const char* kCompensationNames[3] = {"none", "seed", "full"};

std::string magnitude(const SensitivityRow& row) {
  // The star after the unit, a blank where there is none, so that the units line up.
  return fmt::format("{:.3g} {}{}", row.value, row.term.unit, row.typical ? " *" : "  ");
}

std::string row_label(const SensitivityRow& row) {
  if (row.term.harmonic == 0) return row.term.error;
  return fmt::format("{} h{} @{:g}", row.term.error, row.term.harmonic, row.term.phase_rad * kRadToDeg);
}

/// The widest line of the text tables: an 80-column terminal wraps them no more than twice, a 120-column
/// one not at all.
constexpr std::size_t kLineWidth = 118;

/// The first column's width: the longest row label, at least "machine error".
std::size_t label_width(const SensitivityResult& r) {
  std::size_t width = 14;
  for (const SensitivityRow& row : r.rows) width = std::max(width, row_label(row).size() + 2);
  return width;
}

/// `items` joined by `separator`, after `lead` (of `indent` characters), wrapped onto lines indented by
/// `indent` so that no line is longer than kLineWidth.
std::string wrapped(const std::string& lead, std::size_t indent, const std::vector<std::string>& items,
                    std::string_view separator) {
  std::string out = lead;
  std::size_t column = indent;
  for (std::size_t k = 0; k < items.size(); ++k) {
    const std::string piece = items[k] + (k + 1 < items.size() ? std::string(separator) : std::string());
    if (column > indent && column + piece.size() > kLineWidth) {
      while (!out.empty() && out.back() == ' ') out.pop_back();
      out += "\n" + std::string(indent, ' ');
      column = indent;
    }
    out += piece;
    column += piece.size();
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out + "\n";
}

/// docs/physics.md section 15: least squares' shift of each rate error per machine error and compensation, in
/// the rate error's unit (ppm, arcsec); a rate error the plan does not identify is named with its reason.
std::string rate_terms_table(const SensitivityResult& r) {
  const std::size_t width = label_width(r);
  std::string s = fmt::format(
      "\nleast squares, gyro model drift+rate: shift of the rate errors in their units; * = more than {} "
      "sigma\n",
      r.threshold);
  for (std::size_t k = 0; k < kNumRateTerms; ++k) {
    const std::string name(kRateTermNames[k]);
    if (const auto it = r.not_identifiable.find(name); it != r.not_identifiable.end()) {
      s += fmt::format("\n{}: not identifiable: {}\n", name, it->second);
      continue;
    }
    const auto sigma = r.least_squares_noise_std.find(name);
    s += fmt::format("\n{} ({}; sigma {:.3g})\n{:<{}}{:>22}", name, kRateTermUnits[k],
                     sigma != r.least_squares_noise_std.end() ? sigma->second : NAN, "machine error", width,
                     "magnitude");
    for (const char* c : kCompensationNames) s += fmt::format("{:>12}", c);
    if (r.has_self) s += fmt::format("{:>12}", "self");
    s += "\n";
    const auto cell = [&](const ShiftMap& shifts, const std::vector<std::string>& matters) {
      const auto it = shifts.find(name);
      if (it == shifts.end()) return fmt::format("{:>12}", "-");
      const bool m = std::find(matters.begin(), matters.end(), name) != matters.end();
      return fmt::format("{:>12}", fmt::format("{:.3g}{}", it->second, m ? "*" : ""));
    };
    for (const SensitivityRow& row : r.rows) {
      s += fmt::format("{:<{}}{:>22}", row_label(row), width, magnitude(row));
      for (std::size_t c = 0; c < 3; ++c) s += cell(row.least_squares[c], row.least_squares_matters[c]);
      if (r.has_self) s += cell(row.self, row.self_matters);
      s += "\n";
    }
  }
  return s;
}

/// Per compensation, per machine error: the closed forms' estimates it shifts by at least the threshold,
/// each with its shift in units of its noise std ("dI 3.2, dOS -1.1"), the largest first; the full names,
/// wrapped, never a column of truncated names (docs/interface.md, "Text output").
std::string sensitivity_table(const SensitivityResult& r) {
  const std::size_t width = label_width(r), indent = width + 22 + 2;
  std::string s = fmt::format(
      "Each machine error alone (docs/physics.md section 10): shift = estimate(error) - estimate(no error),\n"
      "exact (noise-free). Listed: the estimates shifted by at least {} sigma, as shift / sigma, the "
      "largest\n"
      "first (sigma = the estimate's predicted noise std); - = none. * = typical magnitude (zero in the\n"
      "configuration). @ = a harmonic's phase, deg.\n",
      r.threshold);
  std::vector<std::string> sigmas;
  for (const std::string& name : r.closed_form_names)
    sigmas.push_back(fmt::format("{} {:.2g}", name, r.closed_form_noise_std.at(name)));
  s += "\n" + wrapped("sigma: ", 7, sigmas, ", ");
  const auto header = [&](std::string_view title) {
    return fmt::format("\n{}\n{:<{}}{:>22}  {}\n", title, "machine error", width, "magnitude",
                       "estimates shifted (shift / sigma)");
  };
  for (std::size_t c = 0; c < 3; ++c) {
    s += header(fmt::format("closed forms, compensation {}", kCompensationNames[c]));
    for (const SensitivityRow& row : r.rows) {
      const auto& matters = row.closed_form_matters[c];
      std::vector<std::pair<double, std::string>> shifted;
      for (const std::string& name : r.closed_form_names) {
        const auto it = row.closed_form[c].find(name);
        if (it == row.closed_form[c].end() ||
            std::find(matters.begin(), matters.end(), name) == matters.end())
          continue;
        const double sigma = r.closed_form_noise_std.at(name);
        const double z = sigma > 0 ? it->second / sigma : it->second;
        shifted.emplace_back(std::fabs(z), sigma > 0 ? fmt::format("{} {:.3g}", name, z)
                                                     : fmt::format("{} {:.2e} (no sigma)", name, z));
      }
      std::stable_sort(shifted.begin(), shifted.end(),
                       [](const auto& a, const auto& b) { return a.first > b.first; });
      std::vector<std::string> items;
      for (auto& item : shifted) items.push_back(std::move(item.second));
      if (items.empty()) items.emplace_back("-");
      s += wrapped(fmt::format("{:<{}}{:>22}  ", row_label(row), width, magnitude(row)), indent, items, ", ");
    }
  }
  s += fmt::format("\nleast squares: estimates shifted by more than {} sigma, per compensation\n",
                   r.threshold);
  for (const SensitivityRow& row : r.rows) {
    std::vector<std::string> items;
    const auto names_of = [](const std::vector<std::string>& names) {
      std::string out;
      for (const std::string& n : names) out += (out.empty() ? "" : " ") + n;
      return out.empty() ? std::string("-") : out;
    };
    for (std::size_t c = 0; c < 3; ++c)
      items.push_back(fmt::format("{}: {}", kCompensationNames[c], names_of(row.least_squares_matters[c])));
    // The counter platform's perpendicularity and rate mismatch estimated (docs/self_calibration.md).
    if (r.has_self) items.push_back(fmt::format("self: {}", names_of(row.self_matters)));
    s += wrapped(fmt::format("{:<{}}{:>22}  ", row_label(row), width, magnitude(row)), indent, items, "; ");
  }
  if (r.gyro_model == GyroModel::kDriftRate) s += rate_terms_table(r);
  return s;
}

/// A sensor other than the gyro (docs/accelerometer.md): least squares, the error not told (none) and told
/// (full). Per machine error, the coefficients it shifts by at least the threshold, each with its shift in
/// the coefficient's own unit and in noise sigmas, the largest first.
std::string sensor_sensitivity_table(const SensitivityResult& r) {
  const std::size_t width = label_width(r), indent = width + 22 + 2;
  std::string s = fmt::format(
      "Each machine error alone, {} (least squares): shift = estimate(error) - estimate(no error), exact\n"
      "(noise-free). Listed: the estimates shifted by at least {} sigma, as shift in its unit [shift / "
      "sigma],\n"
      "the largest first (sigma = the estimate's predicted noise std); - = none. * = typical magnitude "
      "(zero\n"
      "in the configuration). @ = a harmonic's phase, deg.\n",
      to_string(r.sensor), r.threshold);
  std::vector<std::string> sigmas;
  for (const std::string& name : r.least_squares_names)
    sigmas.push_back(fmt::format("{} {:.2g} {}", name, r.least_squares_noise_std.at(name), r.units.at(name)));
  s += "\n" + wrapped("sigma: ", 7, sigmas, ", ");
  for (const auto& [name, reason] : r.not_identifiable)
    s += fmt::format("{}: not identifiable: {}\n", name, reason);
  for (const std::size_t c : {std::size_t{0}, std::size_t{2}}) {
    s += fmt::format("\ncompensation {} (the error {} the calibration)\n{:<{}}{:>22}  {}\n",
                     kCompensationNames[c], c == 0 ? "not told" : "told", "machine error", width, "magnitude",
                     "estimates shifted: shift [shift / sigma]");
    for (const SensitivityRow& row : r.rows) {
      const auto& matters = row.least_squares_matters[c];
      std::vector<std::pair<double, std::string>> shifted;
      for (const std::string& name : matters) {
        const double d = row.least_squares[c].at(name);
        const double sigma = r.least_squares_noise_std.at(name);
        const double z = sigma > 0 ? d / sigma : 0.0;
        shifted.emplace_back(sigma > 0 ? std::fabs(z) : std::fabs(d),
                             sigma > 0 ? fmt::format("{} {:.3g} [{:.3g}]", name, d, z)
                                       : fmt::format("{} {:.3g} (no sigma)", name, d));
      }
      std::stable_sort(shifted.begin(), shifted.end(),
                       [](const auto& a, const auto& b) { return a.first > b.first; });
      std::vector<std::string> items;
      for (auto& item : shifted) items.push_back(std::move(item.second));
      if (items.empty()) items.emplace_back("-");
      s += wrapped(fmt::format("{:<{}}{:>22}  ", row_label(row), width, magnitude(row)), indent, items, ", ");
    }
  }
  return s;
}

}  // namespace

void register_sensitivity(CLI::App& app) {
  struct Options {
    std::string config, json;
    std::string gyro_model;  // empty: [calibration] gyro_model
    double threshold = 0.1;
    int threads = 0;
    bool force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "sensitivity",
      "The seed paper's error study (Wang & Meng 2017, the paper this method comes from; docs/physics.md "
      "section 10): the exact shift of every estimate per machine error alone, with each compensation "
      "(none, seed = the paper's correction, full; an accelerometer's: none and full)");
  sub->add_option("--config", opt->config, "Configuration file (TOML); default: the built-in scenario");
  sub->add_option("--json", opt->json, "Write the result as JSON to FILE ('-' = standard output)");
  add_force_flag(sub, opt->force);
  sub->add_option("--threshold", opt->threshold,
                  "An estimate is affected when its shift exceeds this many noise std; default 0.1")
      ->check(kPositiveFinite);
  sub->add_option("--threads", opt->threads,
                  fmt::format("Worker threads, 0 to {}; default (0): all cores", limits::kThreads))
      ->transform(integer_between(0, limits::kThreads));
  add_gyro_model_option(sub, opt->gyro_model);
  sub->callback([opt] {
    refuse_to_overwrite_input(opt->json, opt->config);
    check_output(opt->json, OutputKind::kResult, opt->force, "--json");
    const Scenario scenario = load_configuration(opt->config);
    SensitivityOptions options;
    options.calibration.gyro_model = chosen_gyro_model(opt->gyro_model, scenario);
    options.threshold = opt->threshold;
    options.threads = opt->threads;
    options.calibration.reduce = scenario.reduce;  // [reduce]: the reduction the study's calibrations use
    options.progress = ProgressBar("sensitivity");
    if (scenario.is_imu()) {
      // A whole IMU (docs/imu.md, "Sensitivity of an IMU"): its calibration's options as calibrate builds
      // them (least squares, full compensation, [calibration] estimate), every channel's shifts.
      options.calibration = calibration_options(scenario, CalibrationChoices{});
      const ImuSensitivityResult result = imu_sensitivity_study(scenario, options);
      if (!opt->json.empty()) {
        nlohmann::ordered_json j = imu_sensitivity_to_json(result);
        j["config"] = opt->config.empty() ? nlohmann::json(nullptr) : nlohmann::json(opt->config);
        write_result(opt->json, std::move(j), "sensitivity", opt->force);
      }
      if (opt->json != "-") print_out("{}", imu_sensitivity_table(result));
      return;
    }
    const SensitivityResult result = sensitivity_study(scenario, options);
    if (!opt->json.empty()) {
      nlohmann::json j = sensitivity_to_json(result);
      j["config"] = opt->config.empty() ? nlohmann::json(nullptr) : nlohmann::json(opt->config);
      write_result(opt->json, in_coefficient_order(j, result.sensor), "sensitivity", opt->force);
    }
    if (opt->json != "-")
      print_out("{}", result.sensor == SensorKind::kGyro ? sensitivity_table(result)
                                                         : sensor_sensitivity_table(result));
  });
}

}  // namespace gyrocal::cli
