// An IMU's error study (analysis/sensitivity_imu.hpp): the lone study's rows (sensitivity_terms), each
// through the IMU's planned outputs and joint solve (analysis/predict_imu.hpp).
#include "gyrocal/analysis/sensitivity_imu.hpp"

#include <atomic>
#include <cmath>

#include "gyrocal/analysis/predict_imu.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/parallel.hpp"
#include "gyrocal/identify/imu_calibration.hpp"

namespace gyrocal {
namespace {

/// Every estimate of an IMU's calibration by name: "<channel>.<coefficient>" (identifiable ones), then each
/// estimated error's label; with its unit and std.
struct NamedValue {
  std::string name, unit;
  double value = 0.0, std = 0.0;
};

std::vector<NamedValue> named_estimates(const ImuCalibrationResult& r, std::vector<std::string>* hidden) {
  std::vector<NamedValue> out;
  for (const ImuChannelResult& c : r.channels)
    for (const CoefficientEstimate& e : c.coefficients) {
      const std::string name = c.name + "." + e.name;
      if (!e.identifiable) {
        if (hidden) hidden->push_back(name);
        continue;
      }
      out.push_back({name, e.unit, e.value, e.std});
    }
  for (const MachineErrorEstimate& e : r.machine_errors)
    out.push_back({e.parameter.label(), e.unit, e.value, e.std});
  return out;
}

}  // namespace

ImuSensitivityResult imu_sensitivity_study(const Scenario& scenario, const SensitivityOptions& options) {
  if (!scenario.is_imu())
    throw Error("imu_sensitivity_study takes an IMU's scenario; sensitivity_study takes a lone sensor's.");
  Scenario base = scenario;
  base.errors = CentrifugeErrors{};
  const CentrifugeModel told = base.model();
  const CalibrationOptions o = planned_identify_options(options.calibration);
  const std::vector<std::pair<MachineErrorTerm, double>> terms = sensitivity_terms(scenario.errors);
  // Item 0 the base case, item i the error i - 1 alone on the true machine, the model told none.
  std::vector<ImuCalibrationResult> runs(terms.size() + 1);
  std::atomic<std::size_t> done{0};
  parallel_for(
      runs.size(), options.threads,
      [&](std::size_t i) {
        Scenario truth = base;
        if (i > 0) {
          const auto& [term, value] = terms[i - 1];
          term.add_to(truth.errors, value != 0.0 ? value : term.typical_si);
        }
        runs[i] =
            identify_imu(planned_imu_reductions(base, truth.model(), o.reduce), base.channels(), told, o, {});
        ++done;
      },
      [&] {
        if (options.progress)
          options.progress(static_cast<double>(done.load()) / static_cast<double>(runs.size()));
      });
  if (options.progress) options.progress(1.0);
  ImuSensitivityResult result;
  result.threshold = options.threshold;
  // The predicted noise of each estimate: the base case's (the plan's, on the machine without errors).
  const std::vector<NamedValue> base_estimates = named_estimates(runs[0], &result.not_identifiable);
  for (const NamedValue& e : base_estimates) {
    result.names.push_back(e.name);
    result.units[e.name] = e.unit;
    result.noise_std[e.name] = e.std;
  }
  for (std::size_t i = 0; i < terms.size(); ++i) {
    const auto& [term, value] = terms[i];
    ImuSensitivityRow row;
    row.term = term;
    row.typical = value == 0.0;
    const double amount_si = row.typical ? term.typical_si : value;
    row.value = amount_si / term.unit_to_si;
    const std::vector<NamedValue> with = named_estimates(runs[i + 1], nullptr);
    for (std::size_t k = 0; k < with.size() && k < base_estimates.size(); ++k) {
      const NamedValue& e = with[k];
      double shift = e.value - base_estimates[k].value;
      // An estimated error that is the error studied: its estimate should move by the error itself.
      const MachineErrorParameter* p = nullptr;
      for (const MachineErrorParameter& q : o.estimate)
        if (q.label() == e.name) p = &q;
      if (p != nullptr) {
        CentrifugeErrors with_term;
        term.add_to(with_term, amount_si);
        shift -= p->get(with_term) / p->info().unit_to_si;
      }
      row.shift[e.name] = shift;
      const double sigma = result.noise_std[e.name];
      if (sigma > 0.0 && std::abs(shift) > options.threshold * sigma) row.matters.push_back(e.name);
    }
    result.rows.push_back(std::move(row));
  }
  return result;
}

}  // namespace gyrocal
