#include "residual_levels.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "gyrocal/model/nominal.hpp"

#include "closed_form_identify.hpp"
#include "least_squares_identify.hpp"

namespace gyrocal::identify_detail {
/// A sensor's dwells whose model terms follow the measured motion (PositionModelTerms::sensor_periods), with
/// their covariance's level measured from the scatter between revolutions of the output minus the model
/// (docs/accelerometer_internals.md, "The drive's ripple"): a drive's ripple moves an accelerometer's
/// centripetal input from one revolution to the next by far more than its noise, and that motion is in the
/// model. The model is the design rows at the products of a first least squares on the output's own levels
/// (the estimate is that scatter's weights' only use; the machine errors a self-calibration estimates change
/// the model by far less between revolutions and are left out). nullopt when no dwell follows.
std::optional<Reduction> residual_levels(const Reduction& reduction,
                                         const std::vector<PositionModelTerms>& model_terms,
                                         const CentrifugeModel& model, const CalibrationOptions& options) {
  if (options.sensor == SensorKind::kGyro || model_terms.size() != reduction.positions.size())
    return std::nullopt;
  if (std::none_of(model_terms.begin(), model_terms.end(),
                   [](const PositionModelTerms& c) { return !c.sensor_periods.empty(); }))
    return std::nullopt;
  CalibrationResult first;
  first.g_level =
      radial_level_g(model.site(), model.geometry().radius_m, first_spinning_rate(reduction.positions));
  sensor_least_squares(reduction, model_terms, options, first, ErrorColumns{}, nullptr, &model);
  const std::vector<double>& u = first.products;
  Reduction out = reduction;
  std::vector<std::vector<std::size_t>> slots(out.dwells.size());  // per dwell and gamma slot: its position
  for (std::size_t i = 0; i < out.positions.size(); ++i) {
    const ReducedPosition& p = out.positions[i];
    auto& s = slots[static_cast<std::size_t>(p.dwell)];
    if (s.size() <= static_cast<std::size_t>(p.gamma_slot))
      s.resize(static_cast<std::size_t>(p.gamma_slot) + 1, SIZE_MAX);
    s[static_cast<std::size_t>(p.gamma_slot)] = i;
  }
  for (std::size_t di = 0; di < out.dwells.size(); ++di) {
    DwellValues& v = out.dwells[di].output;
    const std::vector<std::size_t>& s = slots[di];
    if (v.periods.empty() || s.size() != v.value.size() ||
        std::any_of(s.begin(), s.end(),
                    [&](std::size_t i) { return i == SIZE_MAX || model_terms[i].sensor_periods.empty(); }))
      continue;
    std::vector<PeriodValues> residual;
    for (const PeriodValues& pv : v.periods) {
      PeriodValues r{pv.index, pv.t_scaled, pv.values};
      bool found = true;
      for (std::size_t g = 0; g < s.size() && found; ++g) {
        const auto& rows = model_terms[s[g]].sensor_periods;
        const auto it = std::find_if(rows.begin(), rows.end(), [&](const PositionModelTerms::PeriodRow& x) {
          return x.index == pv.index;
        });
        found = it != rows.end();
        if (!found) break;
        double model_value = it->row.known;
        for (std::size_t j = 0; j < it->row.size && j < u.size(); ++j)
          model_value += u[j] * it->row.regressors[j];
        r.values[static_cast<Eigen::Index>(g)] -= model_value;
      }
      if (found) residual.push_back(std::move(r));
    }
    relevel_from_periods(v, residual);
    for (std::size_t g = 0; g < s.size(); ++g) out.positions[s[g]].std_err = v.std_err[g];
  }
  return out;
}

}  // namespace gyrocal::identify_detail
