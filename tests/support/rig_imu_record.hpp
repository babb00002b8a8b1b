#pragma once
// A whole IMU's record as a rig writes it (docs/imu.md, docs/records.md "Increments"), for tests: the machine
// moves as tests/support/rig_record.hpp's RigTrajectory (the rig's own order, ramps, longer dwells, the
// drive's rate offset and ripple), independent of the simulator's timeline. Each row carries every channel
// of the scenario's IMU (Scenario::imu_channels) as an INCREMENT: the integral of the channel's exact output
// (its sensor's model at the exact inputs on its own axes, model/centrifuge.hpp platform_motion and
// sensor/channel.hpp channel_inputs) over the interval that ends at the row's instant, by this generator's
// own composite Simpson rule on the trajectory, plus white noise of the generator's own level, times the
// channel's output_scale. The acquisition: a uniform clock stamped in integer ms, quantised encoders, a
// position encoder toggling by one count, a sample counter that counts every row (lost ones too), rows LOST
// (with their increments: the next row's increment covers its own interval only) and spikes in chosen
// channels.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/sensor/channel.hpp"
#include "gyrocal/sensor/sensor.hpp"
#include "support/rig_record.hpp"

namespace gyrocal::testing {

/// What the IMU rig's acquisition does besides the machine's motion (RigImperfections::rate_offset and
/// ripple act on the trajectory; its stamp and gap members are not used here).
struct RigImuAcquisition {
  double angle_quantum_deg = 0.0;   ///< main and counter encoders quantised to this, deg (0: not)
  double position_count_deg = 0.0;  ///< the position encoder's count, deg; it toggles by one count (0: not)
  std::int64_t start_ms = 0;        ///< the rig's clock at the first row, ms
  std::uint64_t first_count = 0;    ///< the sample counter at the first row
  /// Rows lost, `rows` in a row, the first `at_s` s after the start of dwell `dwell` (its phase in
  /// RigTrajectory: dwells counted in the rig's order from 0).
  struct Lost {
    int dwell = 0;
    double at_s = 0.0;
    int rows = 1;
  };
  std::vector<Lost> lost;
  /// A spike of `size` (deg/h for a gyro channel, g for an accelerometer's, as a mean over the row's
  /// interval) in channel `channel`'s output at the row `at_s` s after the start of dwell `dwell`.
  struct Spike {
    int dwell = 0;
    double at_s = 0.0;
    std::size_t channel = 0;
    double size = 0.0;
  };
  std::vector<Spike> spikes;
  double gyro_arw_deg_rt_h = 0.003;    ///< a gyro channel's white rate noise, deg/sqrt(h)
  double accel_white_ug_rt_hz = 10.0;  ///< an accelerometer channel's white noise density, ug/sqrt(Hz)
  int simpson_panels = 8;              ///< panel pairs of the increments' quadrature per interval
};

/// One row of the IMU rig's record.
struct RigImuRow {
  std::uint64_t count = 0;  ///< the sample counter (every row, lost ones included)
  std::int64_t time_ms = 0;
  double main_angle_deg = 0.0, counter_angle_deg = 0.0, position_angle_deg = 0.0;  ///< as read
  std::vector<double> increments;  ///< per channel, in Scenario::imu_channels' order, in its output units
  JointState truth;                ///< the true joints at the row's instant
};

/// Calls emit(row) for each row of the IMU rig's record of `s` (an IMU scenario: its imu_channels, plan and
/// machine, all its errors), in time order; the first row's increment covers the interval before t = 0 (the
/// machine at rest). `seed` draws the noise and the position encoder's toggling.
inline void rig_imu_rows(const Scenario& s, const RigImperfections& imp, const RigMotion& motion,
                         const RigImuAcquisition& acq, std::uint64_t seed,
                         const std::function<void(const RigImuRow&)>& emit) {
  const CentrifugeModel model = s.model();
  const std::vector<SensorChannel>& channels = s.imu_channels;
  const RigTrajectory trajectory(s, imp, motion);
  const auto& phases = trajectory.phases();
  const double fs = s.test.sample_rate_hz, dt = 1.0 / fs;
  const auto n = static_cast<std::uint64_t>(std::floor(trajectory.duration_s() * fs));

  // The sample index `at_s` s after the start of dwell `dwell`.
  const auto sample_in_dwell = [&](int dwell, double at_s) {
    for (const rig_detail::Phase& p : phases)
      if (p.dwell_index == dwell) return static_cast<std::uint64_t>(std::llround((p.t0 + at_s) * fs));
    return n;  // no such dwell: never reached
  };
  std::vector<std::pair<std::uint64_t, std::uint64_t>> lost;  // [first, end) sample indices
  for (const RigImuAcquisition::Lost& l : acq.lost) {
    const std::uint64_t k = sample_in_dwell(l.dwell, l.at_s);
    lost.emplace_back(k, k + static_cast<std::uint64_t>(l.rows));
  }
  std::vector<std::pair<std::uint64_t, const RigImuAcquisition::Spike*>> spikes;
  for (const RigImuAcquisition::Spike& x : acq.spikes)
    spikes.emplace_back(sample_in_dwell(x.dwell, x.at_s), &x);

  // Each channel's noise-free output (deg/h or g) at time t.
  const auto outputs_at = [&](double t) {
    const PlatformFrameMotion m = platform_motion(model, trajectory.joints(t));
    std::vector<double> y(channels.size());
    for (std::size_t c = 0; c < channels.size(); ++c)
      y[c] = sensor_output(channels[c].sensor, channel_inputs(model, m, channels[c]));
    return y;
  };
  // The white noise of a channel's mean over one interval: a gyro's N deg/sqrt(h) is 60 N deg/h/sqrt(Hz).
  std::vector<double> sigma(channels.size());
  for (std::size_t c = 0; c < channels.size(); ++c)
    sigma[c] = (kind_of(channels[c].sensor) == SensorKind::kGyro ? 60.0 * acq.gyro_arw_deg_rt_h
                                                                 : 1e-6 * acq.accel_white_ug_rt_hz) /
               std::sqrt(dt);
  std::mt19937_64 rng(seed), acquisition(seed ^ 0x9e3779b97f4a7c15ULL);
  std::normal_distribution<double> unit_normal(0.0, 1.0);
  std::bernoulli_distribution toggle(0.5);
  const auto quantise = [](double a, double q) { return q > 0 ? q * std::round(a / q) : a; };

  const int panels = 2 * acq.simpson_panels;
  std::vector<double> left = outputs_at(-dt);  // the output at the interval's start, shared with the last
  for (std::uint64_t k = 0; k < n; ++k) {
    const double tk = static_cast<double>(k) * dt;
    // Composite Simpson over [tk - dt, tk]: weights 1 4 2 4 ... 4 1, times h / 3.
    std::vector<double> sum = left;
    for (int q = 1; q <= panels; ++q) {
      const std::vector<double> y = outputs_at(tk - dt + dt * q / panels);
      const double w = q == panels ? 1.0 : (q % 2 == 1 ? 4.0 : 2.0);
      for (std::size_t c = 0; c < channels.size(); ++c) sum[c] += w * y[c];
      if (q == panels) left = y;
    }
    // Every row is drawn (a lost row's noise too), so losing rows changes no other row's noise.
    RigImuRow row;
    row.increments.resize(channels.size());
    for (std::size_t c = 0; c < channels.size(); ++c) {
      const double mean = sum[c] / (3.0 * panels) + sigma[c] * unit_normal(rng);
      row.increments[c] = channels[c].output.scale * mean * dt;
    }
    const bool toggled = toggle(acquisition);
    if (std::any_of(lost.begin(), lost.end(), [k](const auto& l) { return k >= l.first && k < l.second; }))
      continue;
    for (const auto& [at, x] : spikes)
      if (at == k) row.increments[x->channel] += channels[x->channel].output.scale * x->size * dt;
    const JointState j = trajectory.joints(tk);
    row.count = acq.first_count + k;
    row.time_ms = acq.start_ms + std::llround(tk * 1e3);
    row.main_angle_deg = quantise(std::fmod(j.main_angle_rad * kRadToDeg, 360.0), acq.angle_quantum_deg);
    row.counter_angle_deg = quantise(wrap_deg(j.counter_angle_rad * kRadToDeg), acq.angle_quantum_deg);
    double b = j.position_angle_rad * kRadToDeg;
    if (acq.position_count_deg > 0)
      b = acq.position_count_deg * (std::floor(b / acq.position_count_deg) + (toggled ? 1.0 : 0.0));
    row.position_angle_deg = b;
    row.truth = j;
    emit(row);
  }
}

}  // namespace gyrocal::testing
