#include "gyrocal/identify/channels.hpp"

#include <cmath>

#include "gyrocal/core/parallel.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/planned_channels.hpp"
#include "gyrocal/model/nominal.hpp"

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

}  // namespace

std::vector<PositionChannels> reduce_model_channels(const Reduction& reduction, const CentrifugeModel& model,
                                                    const ReduceOptions& options,
                                                    std::size_t max_samples_per_dwell) {
  // Columns: omega exact, nominal, seed (deg/h), then 10 exact and 10 nominal regressors, then the exact
  // omega_O and omega_S (deg/h; docs/physics.md section 15).
  constexpr int kFirstRegressor = 3;
  constexpr int kOmegaO = kFirstRegressor + 2 * static_cast<int>(kNumCoefficients);
  constexpr int kColumns = kOmegaO + 2;
  std::vector<std::vector<DwellValues>> per_dwell(reduction.dwells.size());
  // Dwells are independent: one per thread, each writing its own slot (the same numbers for any number of
  // threads).
  parallel_for(reduction.dwells.size(), 0, [&](std::size_t di) {
    const Dwell& d = reduction.dwells[di];
    // The reducer's operator, the heading's sweep at a counter rate offset included (docs/physics.md 15).
    const double sweep = d.planned_rate_rad_s != 0.0 ? d.planned_counter_rate_offset_rad_s : 0.0;
    DwellAccumulator acc(options, d.gammas_rad, d.is_static, kColumns, d.planned_duration_s, false, sweep);
    // Every k-th sample (ReduceOptions::model_samples_per_revolution), the last one always: for the harmonic
    // fit and a static hold's mean, which see the channels' smooth shape; a window holds a few samples only,
    // so window means take every sample.
    std::size_t stride = 1;
    // A spinning dwell at a counter rate offset: the Earth rate's horizontal part sweeps with the platform's
    // heading (docs/physics.md section 15), a term outside the fit's harmonics of gamma, whose projection a
    // subsample does not reproduce; every sample is evaluated (at rate 0 the heading is gamma's own
    // harmonic).
    const bool sweeps = d.planned_counter_rate_offset_rad_s != 0.0 && d.planned_rate_rad_s != 0.0;
    const bool smooth_operator =
        !sweeps && (d.is_static || options.method == ReduceOptions::Method::kHarmonicFit);
    if (smooth_operator && options.model_samples_per_revolution > 0 && d.samples > 1) {
      // A revolution is one of gamma: of the main axis without an offset, else at the main rate minus the
      // offset (docs/physics.md section 15).
      const double gamma_rate =
          d.planned_counter_rate_offset_rad_s == 0.0 ? d.main.rate_rad_s : -d.counter.rate_rad_s;
      const double per_period = d.is_static ? static_cast<double>(d.samples) / 64.0
                                            : 2.0 * kPi / std::abs(gamma_rate) / d.sample_interval_s /
                                                  static_cast<double>(options.model_samples_per_revolution);
      stride = static_cast<std::size_t>(std::max(1.0, std::floor(per_period)));
      if (!d.is_static && max_samples_per_dwell > 0 && d.samples / stride > max_samples_per_dwell) {
        const double per_revolution = 2.0 * kPi / std::abs(d.counter.rate_rad_s) / d.sample_interval_s;
        if (std::isfinite(per_revolution) && per_revolution < 1e12)
          stride = long_stride((d.samples + max_samples_per_dwell - 1) / max_samples_per_dwell,
                               d.counter.rate_rad_s * d.sample_interval_s, per_revolution);
      }
    }
    const auto evaluate = [&](double main_rad, double counter_rad, double* v) {
      // The joints on the dwell's constant-rate lines fitted to the encoders (the measured rates); beta as
      // planned (reduce/reducer.cpp: an encoder's mean at rest is biased by up to half a count).
      JointState j;
      j.main_angle_rad = main_rad;
      j.main_rate_rad_s = d.main.rate_rad_s;
      j.counter_angle_rad = counter_rad;
      j.counter_rate_rad_s = d.counter.rate_rad_s;
      j.position_angle_rad = d.beta_rad;
      const GyroInputs exact = exact_inputs(model, j);
      const double offset = d.planned_counter_rate_offset_rad_s;
      const NominalInputs nominal = nominal_inputs(model, j, false, offset);
      v[0] = exact.rate_rad_s.x() * kRadPerSecToDegPerHour;
      v[1] = nominal.omega_I_rad_s * kRadPerSecToDegPerHour;
      v[2] = nominal_inputs(model, j, true, offset).omega_I_rad_s * kRadPerSecToDegPerHour;
      v[kOmegaO] = exact.rate_rad_s.y() * kRadPerSecToDegPerHour;
      v[kOmegaO + 1] = exact.rate_rad_s.z() * kRadPerSecToDegPerHour;
      const auto re = drift_regressors(exact.specific_force_g);
      const auto rn = drift_regressors(Eigen::Vector3d(nominal.a_I_g, nominal.a_O_g, nominal.a_S_g));
      for (std::size_t k = 0; k < kNumCoefficients; ++k) {
        v[kFirstRegressor + k] = re[k];
        v[kFirstRegressor + kNumCoefficients + k] = rn[k];
      }
    };
    // A planned dwell (no stretches: evenly spaced samples on the lines) summed on every sample or for a
    // prediction: in closed form, at a cost independent of its length (identify/planned_channels.hpp).
    if (d.stretches.empty() && (options.model_samples_per_revolution == 0 || max_samples_per_dwell > 0) &&
        planned_dwell_channels(d, options, kColumns, evaluate, per_dwell[di]))
      return;
    double row[kColumns];
    const auto add_sample = [&](double t, double main_rad, double counter_rad) {
      evaluate(main_rad, counter_rad, row);
      acc.add(t, -counter_rad, row);
    };
    if (d.stretches.empty()) {
      const auto at = [&](std::size_t i) {
        const double t = d.time_of_sample(i);
        add_sample(t, d.main.at(t, d.first_time_s), d.counter.at(t, d.first_time_s));
      };
      for (std::size_t i = 0; i + 1 < d.samples; i += stride) at(i);
      if (d.samples > 0) at(d.samples - 1);
    } else {
      // The dwell's own samples, stretch by stretch (gaps and dropped rows as the gyro output has them).
      for (const TimeStretch& s : d.stretches) {
        const auto at = [&](std::size_t i) {
          const double dt = static_cast<double>(i) * s.interval_s;
          add_sample(s.first_time_s + dt, s.main_at_first_rad + d.main.rate_rad_s * dt,
                     s.counter_at_first_rad + d.counter.rate_rad_s * dt);
        };
        for (std::size_t i = 0; i + 1 < s.count; i += stride) at(i);
        if (s.count > 0) at(s.count - 1);
      }
    }
    for (int c = 0; c < kColumns; ++c) per_dwell[di].push_back(acc.finish(c));
  });
  std::vector<PositionChannels> out;
  for (const ReducedPosition& p : reduction.positions) {
    const auto& cols = per_dwell[static_cast<std::size_t>(p.dwell)];
    const auto at = [&](int c) {
      return cols[static_cast<std::size_t>(c)].value[static_cast<std::size_t>(p.gamma_slot)];
    };
    PositionChannels ch;
    ch.omega_exact_deg_h = at(0);
    ch.omega_nominal_deg_h = at(1);
    ch.omega_seed_deg_h = at(2);
    ch.omega_O_exact_deg_h = at(kOmegaO);
    ch.omega_S_exact_deg_h = at(kOmegaO + 1);
    for (std::size_t k = 0; k < kNumCoefficients; ++k) {
      ch.regressors_exact[k] = at(kFirstRegressor + static_cast<int>(k));
      ch.regressors_nominal[k] = at(kFirstRegressor + static_cast<int>(kNumCoefficients + k));
    }
    out.push_back(ch);
  }
  return out;
}

}  // namespace gyrocal
