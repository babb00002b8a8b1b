// The one per-dwell model route (identify/dwell_model_route.hpp): which route a dwell's model columns take,
// and the walk over its samples where no closed form does (the dwell's lines or its measured motion, every
// sample or a stride, the per-revolution fits).
#include "gyrocal/identify/dwell_model_route.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>
#include <variant>

#include "gyrocal/core/parallel.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/planned_model_terms.hpp"
#include "gyrocal/record/increments.hpp"

namespace gyrocal {

namespace {

/// A stride of at least `at_least` samples whose arm-angle step, gamma_step * stride wrapped to (-pi, pi],
/// lies between 2 pi / 40 and 2 pi / 10 in magnitude. The wrapped step changes by gamma_step (< 2 pi / 14)
/// per unit of stride, so the band (wider than 2 pi / 14) is met within one revolution's worth of strides.
std::size_t long_stride(std::size_t at_least, double gamma_step_rad, double samples_per_revolution) {
  const auto tries = static_cast<std::size_t>(std::ceil(samples_per_revolution)) + 2;
  for (std::size_t s = at_least; s < at_least + tries; ++s) {
    const double step = std::abs(wrap_rad(static_cast<double>(s) * gamma_step_rad));
    if (step >= 2.0 * kPi / 40.0 && step <= 2.0 * kPi / 10.0) return s;
  }
  return at_least;  // not reached for >= 14 samples per revolution (reduce/feasibility.hpp)
}

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

}  // namespace

/// Whether dwell d's model terms follow its measured motion (reduce/measured_rate.hpp) rather than its line
/// (docs/calibration.md, "The rate the channels follow"): where the spline departs from the line beyond the
/// readings' scatter (its F-test), the encoder resolves the change (quanta_resolved), and what the line then
/// misses of the specific force at the arm's radius R, the centripetal force's change 2 |w| dw R, the
/// tangential acceleration R dw/dt and the direction's w^2 R dtheta, exceeds kMeasuredRateFloorG.
bool follows_measured_rate(const CentrifugeModel& model, const Dwell& d) {
  const MeasuredMotion& m = d.measured;
  if (m.empty() || !m.resolved || !m.quanta_resolved || m.stretch_phase.size() != d.stretches.size())
    return false;
  return measured_rate_effect_g(model, d) > kMeasuredRateFloorG;
}

namespace {

/// measured_joints at the place k (in the stretch's sample intervals from its first sample, fractional
/// inside an increment's interval) of stretch si.
JointState measured_joints_at(const Dwell& d, std::size_t si, double k) {
  const TimeStretch& s = d.stretches[si];
  const MeasuredMotion& m = d.measured;
  const MeasuredState x = m.at(m.stretch_phase[si], s.first_time_s + k * m.grid_interval_s);
  // The spline's abscissa advances by the planned interval a sample, the stretch's clock by its mean one.
  const double scale = s.interval_s > 0.0 ? m.grid_interval_s / s.interval_s : 1.0;
  const double dt = k * s.interval_s;
  const double deviation = x.angle_rad - (s.main_at_first_rad + d.main.rate_rad_s * dt);
  JointState j;
  j.main_angle_rad = x.angle_rad;
  j.main_rate_rad_s = x.rate_rad_s * scale;
  j.main_accel_rad_s2 = x.accel_rad_s2 * scale * scale;
  j.counter_angle_rad = s.counter_at_first_rad + d.counter.rate_rad_s * dt - deviation;
  j.counter_rate_rad_s = d.counter.rate_rad_s - (j.main_rate_rad_s - d.main.rate_rad_s);
  j.counter_accel_rad_s2 = -j.main_accel_rad_s2;
  j.position_angle_rad = d.beta_rad;
  return j;
}

}  // namespace

JointState measured_joints(const Dwell& d, std::size_t si, std::size_t i) {
  return measured_joints_at(d, si, static_cast<double>(i));
}

double measured_rate_effect_g(const CentrifugeModel& model, const Dwell& d) {
  const MeasuredMotion& m = d.measured;
  const double radius = std::abs(model.geometry().radius_m + model.errors().radius_error_m);
  const double w = std::abs(d.main.rate_rad_s);
  return (2.0 * w * m.max_rate_deviation_rad_s + m.max_accel_rad_s2 + w * w * m.max_angle_deviation_rad) *
         radius / kStandardGravityMS2;
}

namespace {

/// The stride of a dwell's evaluations (every k-th sample, the last one always): 1 unless a stride is
/// configured (ReduceOptions::model_samples_per_revolution) for the harmonic fit or a static hold's mean,
/// which see the model terms' smooth shape (a window holds a few samples only, so window means take every
/// sample), then that many evaluations a revolution of gamma (a static hold: 64 in all), bounded as
/// route.stride_bound says where `bound` > 0.
std::size_t model_stride(const Dwell& d, const ReduceOptions& options, std::size_t bound,
                         const DwellModelRoute& route) {
  // A spinning dwell at a counter rate offset: the Earth rate's horizontal part sweeps with the platform's
  // heading (docs/physics.md section 15), a term outside the fit's harmonics of gamma, whose projection a
  // subsample does not reproduce; every sample is evaluated (at rate 0 the heading is gamma's own
  // harmonic).
  const bool sweeps = d.planned_counter_rate_offset_rad_s != 0.0 && d.planned_rate_rad_s != 0.0;
  const bool smooth_operator =
      !sweeps && (d.is_static || options.method == ReduceOptions::Method::kHarmonicFit);
  if (!smooth_operator || options.model_samples_per_revolution == 0 || d.samples <= 1) return 1;
  // A revolution is one of gamma: of the main axis without an offset, else at the main rate minus the
  // offset (docs/physics.md section 15).
  const double gamma_rate =
      d.planned_counter_rate_offset_rad_s == 0.0 ? d.main.rate_rad_s : -d.counter.rate_rad_s;
  const double per_period = d.is_static ? static_cast<double>(d.samples) / 64.0
                                        : 2.0 * kPi / std::abs(gamma_rate) / d.sample_interval_s /
                                              static_cast<double>(options.model_samples_per_revolution);
  std::size_t stride = static_cast<std::size_t>(std::max(1.0, std::floor(per_period)));
  if (bound == 0) return stride;
  switch (route.stride_bound) {
    case ModelStrideBound::kArmAngleBand:
      if (!d.is_static && d.samples / stride > bound) {
        const double per_revolution = 2.0 * kPi / std::abs(d.counter.rate_rad_s) / d.sample_interval_s;
        if (std::isfinite(per_revolution) && per_revolution < 1e12)
          stride = long_stride((d.samples + bound - 1) / bound, d.counter.rate_rad_s * d.sample_interval_s,
                               per_revolution);
      }
      return stride;
    case ModelStrideBound::kEvenSpread:
      return std::max(stride, (d.samples + bound - 1) / bound);
  }
  return stride;
}

/// The revolutions' own fits of a dwell's model columns, as the output's scatter takes them
/// (DwellAccumulator: a revolution of the basis angle from the first sample, a harmonic fit without drift,
/// kept when it holds two samples a parameter), where the model changes from one revolution to the next.
class RevolutionFits {
 public:
  RevolutionFits(const Dwell& d, const ReduceOptions& options, int columns, bool active)
      : d_(d), options_(options), columns_(columns), active_(active) {}

  /// The sample just added to the dwell's accumulator (its `samples_so_far`-th) at gamma_rad, its columns.
  void add(std::size_t samples_so_far, double gamma_rad, const double* values) {
    if (!active_) return;
    if (samples_so_far == 1) gamma_first_ = gamma_rad;
    const int rev = DwellAccumulator::revolution(gamma_rad, gamma_first_);
    if (rev != revolution_) close();
    revolution_ = rev;
    if (!fit_) fit_.emplace(d_.gammas_rad, options_.harmonic_order, false, columns_, false);
    fit_->add(0.0, gamma_rad, values);
  }

  /// Ends the revolution in progress: its values at the dwell's gammas kept if it holds enough samples.
  void close() {
    if (!fit_) return;
    const int nr = 2 * options_.harmonic_order + 1;
    if (fit_->samples() >= static_cast<std::size_t>(2 * nr)) {
      Eigen::MatrixXd values(static_cast<Eigen::Index>(d_.gammas_rad.size()), columns_);
      DwellValues out;
      out.value.assign(d_.gammas_rad.size(), 0.0);
      out.samples.assign(d_.gammas_rad.size(), 0);
      for (int c = 0; c < columns_; ++c) {
        fit_->values(c, 0.0, out);
        for (std::size_t k = 0; k < d_.gammas_rad.size(); ++k)
          values(static_cast<Eigen::Index>(k), c) = out.value[k];
      }
      kept_.push_back({revolution_, std::move(values)});
    }
    fit_.reset();
  }

  std::vector<RevolutionModelValues> take() { return std::move(kept_); }

 private:
  const Dwell& d_;
  const ReduceOptions& options_;
  int columns_;
  bool active_;
  std::optional<HarmonicFit> fit_;
  int revolution_ = 0;
  double gamma_first_ = 0.0;
  std::vector<RevolutionModelValues> kept_;
};

}  // namespace

DwellModelValues reduce_dwell_model(const CentrifugeModel& model, const Dwell& d,
                                    const ReduceOptions& options, std::size_t max_samples_per_dwell,
                                    ModelTermsRoute closed_forms, const DwellModelRoute& route,
                                    const JointModelColumns& evaluate) {
  DwellModelValues out;
  const int columns = route.columns;
  // The reducer's operator, the heading's sweep at a counter rate offset included (docs/physics.md 15).
  const double sweep = d.planned_rate_rad_s != 0.0 ? d.planned_counter_rate_offset_rad_s : 0.0;
  DwellAccumulator acc(options, d.gammas_rad, d.is_static, columns, d.planned_duration_s, false, sweep);
  // The columns with the joints on the dwell's constant-rate lines fitted to the encoders (the measured mean
  // rates), beta as planned: what the closed forms expand.
  const DwellModelTermsEvaluator on_lines = [&](double main_rad, double counter_rad, double* row) {
    evaluate(d, line_joints(d, main_rad, counter_rad), row);
  };
  // A record's dwell whose arm departs from its line (a drive's ripple): every sample on the measured motion.
  const bool follow = follows_measured_rate(model, d);
  out.route.measured_rate = follow;
  // A planned dwell (no stretches: evenly spaced samples on the lines) summed on every sample or for a
  // prediction: in closed form, at a cost independent of its length (identify/planned_model_terms.hpp).
  if (route.planned_closed_form && !route.interval_mean && closed_forms == ModelTermsRoute::kExact &&
      d.stretches.empty() && (options.model_samples_per_revolution == 0 || max_samples_per_dwell > 0) &&
      planned_dwell_model_terms(d, options, columns, on_lines, out.columns))
    return out;
  // Every sample asked for: the same sums by closed forms when the series' check holds (the joints on the
  // dwell's lines, so not where they follow the measured motion).
  const bool exact_requested = options.model_samples_per_revolution == 0 &&
                               (d.is_static || options.method == ReduceOptions::Method::kHarmonicFit);
  if (!follow && exact_requested && closed_forms == ModelTermsRoute::kExact &&
      reduce_dwell_by_fourier(model, d, options, acc, columns, route.rate_columns, on_lines, out.route,
                              route.interval_mean ? d.sample_interval_s : 0.0)) {
    for (int c = 0; c < columns; ++c) out.columns.push_back(acc.finish(c));
    return out;
  }
  // Sample by sample. Following the measured motion, the revolutions' own fits beside the dwell's where asked
  // for (the harmonic fit only: window means and static holds have no revolutions).
  RevolutionFits revolutions(
      d, options, columns,
      route.per_revolution && follow && std::holds_alternative<HarmonicFit>(acc.reduction()));
  std::vector<double> v(static_cast<std::size_t>(columns));
  // An increment's model (route.interval_mean): the columns' mean over the sample's interval [t - dt, t] by
  // Gauss-Legendre, with enough nodes for 1e-13 at twice the Fourier route's first band (record/
  // increments.hpp); `back(s)` gives the joints s seconds before the stamp.
  const double mean_dt = route.interval_mean ? d.sample_interval_s : 0.0;
  const IntervalRule rule = interval_rule(
      mean_dt > 0.0 ? interval_nodes(2.0 * fourier_harmonics(model) *
                                     (std::abs(d.main.rate_rad_s) + std::abs(d.counter.rate_rad_s)) * mean_dt)
                    : 1);
  std::vector<double> node(static_cast<std::size_t>(columns));
  const auto add = [&](double t, const JointState& j, const auto& back, double gamma_rad) {
    if (mean_dt > 0.0) {
      std::fill(v.begin(), v.end(), 0.0);
      for (std::size_t k = 0; k < rule.back.size(); ++k) {
        evaluate(d, back(rule.back[k] * mean_dt), node.data());
        for (std::size_t c = 0; c < v.size(); ++c) v[c] += rule.weight[k] * node[c];
      }
    } else {
      evaluate(d, j, v.data());
    }
    acc.add(t, gamma_rad, v.data());
    revolutions.add(acc.samples(), gamma_rad, v.data());
  };
  const auto add_on_lines = [&](double t, double main_rad, double counter_rad) {
    add(
        t, line_joints(d, main_rad, counter_rad),
        [&](double back_s) {
          return line_joints(d, main_rad - d.main.rate_rad_s * back_s,
                             counter_rad - d.counter.rate_rad_s * back_s);
        },
        -counter_rad);
  };
  const std::size_t stride = model_stride(d, options, max_samples_per_dwell, route);
  if (d.stretches.empty()) {
    const auto at = [&](std::size_t i) {
      const double t = d.time_of_sample(i);
      add_on_lines(t, d.main.at(t, d.first_time_s), d.counter.at(t, d.first_time_s));
    };
    for (std::size_t i = 0; i + 1 < d.samples; i += stride) at(i);
    if (d.samples > 0) at(d.samples - 1);
  } else {
    // The dwell's own samples, stretch by stretch (gaps and dropped rows as the output has them).
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
          // The joints follow the measured motion, and the operator's gamma is the output's own
          // (Dwell::basis_angle), which a ripple bends window by window: the dwell's one line is not it.
          add(
              s.first_time_s + dt, measured_joints(d, si, i),
              [&](double back_s) {
                // An increment's interval reaches back across the stretch's start: the spline is held at its
                // first knot there (MeasuredMotion::at).
                return measured_joints_at(d, si, static_cast<double>(i) - back_s / s.interval_s);
              },
              d.basis_angle.empty() ? -counter_line : -basis.at(first_sample + i, s.first_time_s + dt));
        else
          add_on_lines(s.first_time_s + dt, s.main_at_first_rad + d.main.rate_rad_s * dt, counter_line);
      };
      for (std::size_t i = 0; i + 1 < s.count; i += stride) at(i);
      if (s.count > 0) at(s.count - 1);
      first_sample += s.count;
    }
  }
  revolutions.close();
  out.revolutions = revolutions.take();
  for (int c = 0; c < columns; ++c) out.columns.push_back(acc.finish(c));
  return out;
}

std::vector<DwellModelValues> reduce_dwells_model(const Reduction& reduction, const CentrifugeModel& model,
                                                  const ReduceOptions& options,
                                                  std::size_t max_samples_per_dwell,
                                                  ModelTermsRoute closed_forms, const DwellModelRoute& route,
                                                  const JointModelColumns& evaluate) {
  std::vector<DwellModelValues> out(reduction.dwells.size());
  // Dwells are independent: one per thread, each writing its own slot (the same numbers for any number of
  // threads).
  parallel_for(reduction.dwells.size(), 0, [&](std::size_t di) {
    out[di] = reduce_dwell_model(model, reduction.dwells[di], options, max_samples_per_dwell, closed_forms,
                                 route, evaluate);
  });
  return out;
}

std::vector<DwellModelTermsRoute> dwell_routes(const std::vector<DwellModelValues>& dwells) {
  std::vector<DwellModelTermsRoute> out;
  out.reserve(dwells.size());
  for (const DwellModelValues& d : dwells) out.push_back(d.route);
  return out;
}

}  // namespace gyrocal
