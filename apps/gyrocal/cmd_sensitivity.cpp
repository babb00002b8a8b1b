// gyrocal sensitivity: the seed's error study (docs/physics.md section 10, docs/contract.md).
#include <unistd.h>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/analysis/sensitivity.hpp"
#include "gyrocal/identify/unknowns.hpp"
#include "gyrocal/result/sensitivity_json.hpp"

namespace gyrocal::cli {
namespace {

constexpr const char* kCompensationNames[3] = {"none", "seed", "full"};

std::string magnitude(const SensitivityRow& row) {
  return fmt::format("{:.3g} {}{}", row.value, row.term.unit, row.typical ? " *" : "");
}

std::string row_label(const SensitivityRow& row) {
  if (row.term.harmonic == 0) return row.term.error;
  return fmt::format("{} h{} @{:g}", row.term.error, row.term.harmonic, row.term.phase_rad * kRadToDeg);
}

/// docs/physics.md section 15: least squares' shift of each rate error per machine error and compensation, in
/// the rate error's unit (ppm, arcsec); a rate error the plan does not identify is named with its reason.
std::string rate_terms_table(const SensitivityResult& r) {
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
    s += fmt::format("\n{} ({}; sigma {:.3g})\n{:<30}{:>18}", name, kRateTermUnits[k],
                     sigma != r.least_squares_noise_std.end() ? sigma->second : NAN, "machine error",
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
      s += fmt::format("{:<30}{:>18}", row_label(row), magnitude(row));
      for (std::size_t c = 0; c < 3; ++c) s += cell(row.least_squares[c], row.least_squares_matters[c]);
      if (r.has_self) s += cell(row.self, row.self_matters);
      s += "\n";
    }
  }
  return s;
}

/// Per compensation: the closed forms' shifts in units of their noise std, '.' below the threshold.
std::string sensitivity_table(const SensitivityResult& r) {
  std::string s = fmt::format(
      "Each machine error alone (docs/physics.md section 10): shift = estimate(error) - estimate(no error), "
      "exact "
      "(noise-free).\nCells: shift / sigma, sigma = the estimate's predicted noise std; '.' = below {} sigma "
      "(does not matter). * = typical magnitude (zero in the configuration).\n",
      r.threshold);
  s += "\nsigma:";
  for (const std::string& name : r.closed_form_names)
    s += fmt::format("  {} {:.2g}", name, r.closed_form_noise_std.at(name));
  s += "\n";
  for (std::size_t c = 0; c < 3; ++c) {
    s += fmt::format("\nclosed forms, compensation {}\n{:<30}{:>18}", kCompensationNames[c], "machine error",
                     "magnitude");
    for (const std::string& name : r.closed_form_names) s += fmt::format("{:>9}", name.substr(0, 8));
    s += "\n";
    for (const SensitivityRow& row : r.rows) {
      s += fmt::format("{:<30}{:>18}", row_label(row), magnitude(row));
      const auto& matters = row.closed_form_matters[c];
      for (const std::string& name : r.closed_form_names) {
        const auto it = row.closed_form[c].find(name);
        const bool m = std::find(matters.begin(), matters.end(), name) != matters.end();
        const double sigma = r.closed_form_noise_std.at(name);
        if (it == row.closed_form[c].end() || !m)
          s += fmt::format("{:>9}", ".");
        else if (sigma > 0)
          s += fmt::format("{:>9.3g}", it->second / sigma);
        else
          s += fmt::format("{:>9.2e}", it->second);
      }
      s += "\n";
    }
  }
  s += fmt::format("\nleast squares: estimates shifted by more than {} sigma\n", r.threshold);
  for (const SensitivityRow& row : r.rows) {
    std::string line;
    for (std::size_t c = 0; c < 3; ++c) {
      std::string names;
      for (const std::string& n : row.least_squares_matters[c]) names += (names.empty() ? "" : " ") + n;
      line += fmt::format("  {}: {:<28}", kCompensationNames[c], names.empty() ? "-" : names);
    }
    if (r.has_self) {
      // The counter platform's perpendicularity and rate mismatch estimated (docs/self_calibration.md).
      std::string names;
      for (const std::string& n : row.self_matters) names += (names.empty() ? "" : " ") + n;
      line += fmt::format("  self: {:<28}", names.empty() ? "-" : names);
    }
    s += fmt::format("{:<30}{:>18}{}\n", row_label(row), magnitude(row), line);
  }
  if (r.gyro_model == GyroModel::kDriftRate) s += rate_terms_table(r);
  return s;
}

}  // namespace

void register_sensitivity(CLI::App& app) {
  struct Options {
    std::string config, json;
    std::string gyro_model;  // empty: [calibration] gyro_model
    double threshold = 0.1;
    int threads = 0;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "sensitivity",
      "The seed's study: the shift of every estimate per machine error, with each compensation");
  sub->add_option("--config", opt->config, "Configuration file (TOML); default: the built-in scenario");
  sub->add_option("--json", opt->json, "Write the result as JSON to FILE ('-' = standard output)");
  sub->add_option("--threshold", opt->threshold,
                  "An estimate is affected when its shift exceeds this many noise std; default 0.1")
      ->check(kFinite & CLI::PositiveNumber);
  sub->add_option("--threads", opt->threads, "Worker threads; default: all cores")
      ->check(CLI::NonNegativeNumber);
  add_gyro_model_option(sub, opt->gyro_model);
  sub->callback([opt] {
    refuse_to_overwrite_input(opt->json, opt->config);
    const Scenario scenario = load_configuration(opt->config);
    SensitivityOptions options;
    options.calibration.gyro_model = chosen_gyro_model(opt->gyro_model, scenario);
    options.threshold = opt->threshold;
    options.threads = opt->threads;
    options.calibration.reduce = scenario.reduce;  // [reduce]: the reduction the study's calibrations use
    if (::isatty(STDERR_FILENO)) options.progress = ProgressBar("sensitivity");
    const SensitivityResult result = sensitivity_study(scenario, options);
    if (!opt->json.empty()) write_output(opt->json, sensitivity_to_json(result).dump(2) + "\n", true);
    if (opt->json != "-") fmt::print("{}", sensitivity_table(result));
  });
}

}  // namespace gyrocal::cli
