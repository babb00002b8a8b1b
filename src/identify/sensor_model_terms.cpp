#include "gyrocal/identify/sensor_model_terms.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>
#include <variant>

#include "gyrocal/core/parallel.hpp"
#include "gyrocal/core/units.hpp"

namespace gyrocal {
namespace {

/// The joints on a dwell's lines: the main and counter angles given (rad), their rates the lines', beta the
/// dwell's.
JointState line_joints(const Dwell& d, double main_rad, double counter_rad) {
  JointState j;
  j.main_angle_rad = main_rad;
  j.main_rate_rad_s = d.main.rate_rad_s;
  j.counter_angle_rad = counter_rad;
  j.counter_rate_rad_s = d.counter.rate_rad_s;
  j.position_angle_rad = d.beta_rad;
  return j;
}

/// The sensor's design row at the joints (the encoders at the output's stamp) as the reduction's columns: the
/// known part, then the regressors; at the inputs the output holds (sensed_inputs: the acquisition's delay).
void design_columns(const Sensor& sensor, const CentrifugeModel& model, const JointState& j, double* out) {
  const DesignRow row = sensor_design_row(sensor, sensed_inputs(model, j));
  out[0] = row.known;
  for (std::size_t k = 0; k < row.size; ++k) out[k + 1] = row.regressors[k];
}

}  // namespace

std::vector<double> harmonic_content_gammas_rad(int harmonic_order) {
  const int n = 2 * std::max(harmonic_order, 0) + 1;
  std::vector<double> out;
  for (int k = 0; k < n; ++k) out.push_back(2.0 * kPi * k / n);
  return out;
}

TestSpec reduction_plan(const TestSpec& plan, SensorKind sensor, const ReduceOptions& options) {
  TestSpec out = plan;
  if (sensor == SensorKind::kAccelerometer && options.method == ReduceOptions::Method::kHarmonicFit)
    out.spinning_gamma_rad = harmonic_content_gammas_rad(options.harmonic_order);
  return out;
}

std::vector<PositionModelTerms> reduce_sensor_model_terms(const Reduction& reduction,
                                                          const CentrifugeModel& model,
                                                          const ReduceOptions& options, const Sensor& sensor,
                                                          std::size_t max_samples_per_dwell,
                                                          ModelTermsRoute route,
                                                          std::vector<DwellModelTermsRoute>* routes) {
  const DesignRow probe = sensor_design_row(sensor, exact_inputs(model, JointState{}));
  const int columns = 1 + static_cast<int>(probe.size);
  // The design row's known part and regressors are in the output's unit and its powers (g, g^2, g^3): no
  // column is a difference of the joints' rates.
  const std::vector<bool> rate_columns(static_cast<std::size_t>(columns), false);
  std::vector<std::vector<DwellValues>> per_dwell(reduction.dwells.size());
  // Following dwells: per revolution, its index and the columns' values at each gamma (gamma x column).
  std::vector<std::vector<std::pair<int, Eigen::MatrixXd>>> per_revolution(reduction.dwells.size());
  std::vector<DwellModelTermsRoute> chosen(reduction.dwells.size());
  parallel_for(reduction.dwells.size(), 0, [&](std::size_t di) {
    const Dwell& d = reduction.dwells[di];
    // The reducer's operator, the heading's sweep at a counter rate offset included (as the gyro's model
    // terms).
    const double sweep = d.planned_rate_rad_s != 0.0 ? d.planned_counter_rate_offset_rad_s : 0.0;
    DwellAccumulator acc(options, d.gammas_rad, d.is_static, columns, d.planned_duration_s, false, sweep);
    std::vector<double> v(static_cast<std::size_t>(columns));
    // The joints as identify/model_terms.cpp takes them: on the dwell's constant-rate lines fitted to the
    // encoders, beta as planned; or, where the drive's rate ripples (follows_measured_rate), the arm's
    // measured motion (measured_joints: its angle, rate and angular acceleration at the sample), while the
    // operator's gamma stays the line's. An accelerometer reads the centripetal force, first order in the
    // rate.
    const bool follow = follows_measured_rate(model, d);
    chosen[di].measured_rate = follow;
    // Every sample asked for: the same sums by closed forms when the series' check holds
    // (reduce_dwell_by_fourier; the joints on the dwell's lines, so not where they follow the measured
    // motion).
    const bool exact_requested = options.model_samples_per_revolution == 0 &&
                                 (d.is_static || options.method == ReduceOptions::Method::kHarmonicFit);
    if (!follow && exact_requested && route == ModelTermsRoute::kExact) {
      const DwellModelTermsEvaluator evaluate = [&](double main_rad, double counter_rad, double* row_out) {
        design_columns(sensor, model, line_joints(d, main_rad, counter_rad), row_out);
      };
      if (reduce_dwell_by_fourier(model, d, options, acc, columns, rate_columns, evaluate, chosen[di])) {
        for (int c = 0; c < columns; ++c) per_dwell[di].push_back(acc.finish(c));
        return;
      }
    }
    // The revolutions' own fits, as the output's scatter takes them (DwellAccumulator: a revolution of the
    // basis angle from the first sample, a harmonic fit without drift when it holds two samples a
    // parameter), where the model changes from one revolution to the next: following the measured motion.
    const bool per_rev = follow && std::holds_alternative<HarmonicFit>(acc.reduction());
    std::optional<HarmonicFit> rev_fit;
    int revolution = 0;
    double gamma_first = 0.0;
    const auto close_revolution = [&] {
      if (!rev_fit) return;
      const int nr = 2 * options.harmonic_order + 1;
      if (rev_fit->samples() >= static_cast<std::size_t>(2 * nr)) {
        Eigen::MatrixXd values(static_cast<Eigen::Index>(d.gammas_rad.size()), columns);
        DwellValues out;
        out.value.assign(d.gammas_rad.size(), 0.0);
        out.samples.assign(d.gammas_rad.size(), 0);
        for (int c = 0; c < columns; ++c) {
          rev_fit->values(c, 0.0, out);
          for (std::size_t k = 0; k < d.gammas_rad.size(); ++k)
            values(static_cast<Eigen::Index>(k), c) = out.value[k];
        }
        per_revolution[di].emplace_back(revolution, std::move(values));
      }
      rev_fit.reset();
    };
    const auto add_joints = [&](double t, const JointState& j, double gamma_rad) {
      design_columns(sensor, model, j, v.data());
      acc.add(t, gamma_rad, v.data());
      if (!per_rev) return;
      if (acc.samples() == 1) gamma_first = gamma_rad;
      const int rev = DwellAccumulator::revolution(gamma_rad, gamma_first);
      if (rev != revolution) close_revolution();
      revolution = rev;
      if (!rev_fit) rev_fit.emplace(d.gammas_rad, options.harmonic_order, false, columns, false);
      rev_fit->add(0.0, gamma_rad, v.data());
    };
    const auto add_sample = [&](double t, double main_rad, double counter_rad) {
      add_joints(t, line_joints(d, main_rad, counter_rad), -counter_rad);
    };
    std::size_t stride = 1;
    const bool sweeps = d.planned_counter_rate_offset_rad_s != 0.0 && d.planned_rate_rad_s != 0.0;
    if (!sweeps && options.model_samples_per_revolution > 0 && d.samples > 1 &&
        (d.is_static || options.method == ReduceOptions::Method::kHarmonicFit)) {
      const double gamma_rate =
          d.planned_counter_rate_offset_rad_s == 0.0 ? d.main.rate_rad_s : -d.counter.rate_rad_s;
      const double per_period = d.is_static ? static_cast<double>(d.samples) / 64.0
                                            : 2.0 * kPi / std::abs(gamma_rate) / d.sample_interval_s /
                                                  static_cast<double>(options.model_samples_per_revolution);
      stride = static_cast<std::size_t>(std::max(1.0, std::floor(per_period)));
      if (max_samples_per_dwell > 0)
        stride = std::max(stride, (d.samples + max_samples_per_dwell - 1) / max_samples_per_dwell);
    }
    if (d.stretches.empty()) {
      const auto at = [&](std::size_t i) {
        const double t = d.time_of_sample(i);
        add_sample(t, d.main.at(t, d.first_time_s), d.counter.at(t, d.first_time_s));
      };
      for (std::size_t i = 0; i + 1 < d.samples; i += stride) at(i);
      if (d.samples > 0) at(d.samples - 1);
    } else {
      // Following the measured motion, the operator's angle is the output's own (Dwell::basis_angle): where
      // a ripple bends the counter encoder's line window by window, the dwell's one line is not it.
      BasisAngleCursor basis(d.basis_angle);
      LeftOutSamples left_out(d.output.outlier_samples);
      std::size_t first_sample = 0;
      for (std::size_t si = 0; si < d.stretches.size(); ++si) {
        const TimeStretch& s = d.stretches[si];
        const auto at = [&](std::size_t i) {
          const double dt = static_cast<double>(i) * s.interval_s;
          const double counter_line = s.counter_at_first_rad + d.counter.rate_rad_s * dt;
          if (follow && left_out.contains(first_sample + i)) return;
          if (follow)
            add_joints(
                s.first_time_s + dt, measured_joints(d, si, i),
                d.basis_angle.empty() ? -counter_line : -basis.at(first_sample + i, s.first_time_s + dt));
          else
            add_sample(s.first_time_s + dt, s.main_at_first_rad + d.main.rate_rad_s * dt, counter_line);
        };
        for (std::size_t i = 0; i + 1 < s.count; i += stride) at(i);
        if (s.count > 0) at(s.count - 1);
        first_sample += s.count;
      }
    }
    close_revolution();
    for (int c = 0; c < columns; ++c) per_dwell[di].push_back(acc.finish(c));
  });
  if (routes) *routes = std::move(chosen);
  std::vector<PositionModelTerms> out;
  for (const ReducedPosition& p : reduction.positions) {
    const auto& cols = per_dwell[static_cast<std::size_t>(p.dwell)];
    const auto at = [&](int c) {
      return cols[static_cast<std::size_t>(c)].value[static_cast<std::size_t>(p.gamma_slot)];
    };
    PositionModelTerms ch;
    ch.sensor_exact.known = at(0);
    ch.sensor_exact.size = probe.size;
    for (std::size_t k = 0; k < probe.size; ++k) ch.sensor_exact.regressors[k] = at(static_cast<int>(k) + 1);
    for (const auto& [index, values] : per_revolution[static_cast<std::size_t>(p.dwell)]) {
      PositionModelTerms::PeriodRow pr;
      pr.index = index;
      const auto g = static_cast<Eigen::Index>(p.gamma_slot);
      pr.row.known = values(g, 0);
      pr.row.size = probe.size;
      for (std::size_t k = 0; k < probe.size; ++k)
        pr.row.regressors[k] = values(g, static_cast<Eigen::Index>(k) + 1);
      ch.sensor_periods.push_back(pr);
    }
    out.push_back(ch);
  }
  return out;
}

}  // namespace gyrocal
