#pragma once
// A record as a rig writes it (docs/physics.md section 14), for tests: independent of the simulator's
// timeline (plan/timeline.hpp). The machine starts at rest, ramps smoothly to each rate, moves the position
// platform smoothly between dwells, and visits the plan's (rate, beta) pairs in an order of its own, each
// dwell longer than planned. Its drive turns at the planned rate times (1 + offset), with a sinusoidal
// ripple. The output is the scenario's sensor at the generator's own joint states: a gyro's exact model
// (model/centrifuge.hpp exact_inputs, model/gyro.hpp) plus white noise, or, for an accelerometer scenario
// ([sensor] kind = "accelerometer"), the IEEE 1293 model (sensor/accelerometer.hpp) at the exact specific
// force, in its output units (K1 per g), with its [accelerometer.noise]. A rate of 0 is a static set: the
// main axis stopped and the counter platform indexed to each gamma. What the acquisition then does to it: a
// uniform clock read with jitter and rounded, quantised angle encoders, a position encoder toggling by one
// count, a gap, a clock jump, spikes in the output, a glitch of beta in one row.
//
// rig_rows() yields rows of numbers (physical units); write_native() writes gyrocal's own format. Another
// layout (encoder counts, ms, ';', mV) is another writer over the same rows.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <ostream>
#include <random>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/model/gyro.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/sensor/accelerometer.hpp"
#include "gyrocal/simulate/accelerometer_noise.hpp"

namespace gyrocal::testing {

/// What the rig does to a record. Defaults: a perfect rig (but its own order, ramps and longer dwells).
struct RigImperfections {
  double jitter_s = 0.0;            ///< time stamps read with uniform jitter of +- this, s
  double stamp_resolution_s = 0.0;  ///< stamps rounded to this, s (0: not rounded)
  double angle_quantum_deg = 0.0;   ///< main and counter encoders quantised to this, deg
  double position_count_deg = 0.0;  ///< the position encoder's count, deg; at rest it toggles by one count
  double rate_offset = 0.0;         ///< the drive turns at planned x (1 + this)
  double ripple = 0.0;              ///< relative amplitude of the drive's rate ripple
  double ripple_hz = 0.37;          ///< its frequency, Hz
  double gap_fraction = 0.0;        ///< rows missing from the middle of the third dwell: this fraction of it
  double clock_jump_s = 0.0;        ///< the clock jumps by this in the middle of the fifth dwell
  int spikes = 0;  ///< output spikes of spike_deg_h (a gyro's) or spike_g, spread over the record
  double spike_deg_h = 1e6;
  double spike_g = 1.0;                 ///< an accelerometer's spike, g (K1 x this in output units)
  double beta_glitch_deg = 0.0;         ///< one row in the middle of the second dwell reads beta off by this
  double beta_move_in_dwell_deg = 0.0;  ///< beta moves by this 0.5 s into the settle time of the fourth dwell
};

/// The generator's own choices of the machine's motion.
struct RigMotion {
  double ramp_s = 4.0;         ///< a smooth ramp between two rates
  double move_s = 3.0;         ///< a smooth move of the position platform
  double extra_dwell_s = 3.0;  ///< each dwell lasts settle + planned + this
  double noise_deg_h = 0.5;    ///< white noise on each output sample, deg/h (a gyro's; an accelerometer's is
                               ///< its scenario's [accelerometer.noise])
};

/// One row in physical units.
struct RigRow {
  double time_s = 0.0;
  double main_angle_deg = 0.0, counter_angle_deg = 0.0, position_angle_deg = 0.0;
  double output = 0.0;
  JointState truth;  ///< the machine's true joints at the sample's instant (for tests of the model's side)
};

namespace rig_detail {

/// A smooth step from 0 to 1 over [0, 1] and its integral and derivatives.
inline double step(double u) {
  return u <= 0 ? 0.0 : u >= 1 ? 1.0 : 0.5 * (1.0 - std::cos(kPi * u));
}
inline double step_rate(double u) {
  return u <= 0 || u >= 1 ? 0.0 : 0.5 * kPi * std::sin(kPi * u);
}

struct Phase {
  double t0 = 0.0, t1 = 0.0;
  double rate0 = 0.0, rate1 = 0.0;  // the drive's rate at its start and end (a ramp when they differ)
  double beta0 = 0.0, beta1 = 0.0;  // rad (a move when they differ)
  double theta0 = 0.0;              // main angle at t0
  // The counter platform: servoed (psi_r = psi0 - theta, the platform keeps its heading) while the main axis
  // turns, else indexed from counter0 to counter1 (rad; a move when they differ) with the main axis stopped.
  bool servoed = true;
  double psi0 = 0.0;
  double counter0 = 0.0, counter1 = 0.0;
  bool dwell = false;
  int dwell_index = -1;
};

}  // namespace rig_detail

/// Every imperfection of docs/physics.md section 14 at once, at the level the reduction must take.
inline RigImperfections every_imperfection() {
  RigImperfections all;
  all.jitter_s = 1e-4;
  all.stamp_resolution_s = 1e-3;
  all.angle_quantum_deg = 0.1;
  all.position_count_deg = 0.002;
  all.rate_offset = 1e-3;
  all.ripple = 2e-4;
  all.gap_fraction = 0.1;
  all.clock_jump_s = 1000.0;
  all.spikes = 6;
  all.beta_glitch_deg = 30.0;
  return all;
}

/// The machine's motion of a rig's record of a scenario's plan: the phases (rest, ramps, moves, dwells in
/// the rig's own order) and the true joints at any instant. A spinning rate is one dwell per beta; a rate of
/// 0 one hold per beta and gamma (the rig's own gamma order), each lasting settle + the planned hold + extra.
class RigTrajectory {
 public:
  RigTrajectory(const Scenario& s, const RigImperfections& imp, const RigMotion& motion) : imp_(imp) {
    using rig_detail::Phase;
    const TestSpec& test = s.test;
    // The rig's own order: rates last to first, betas rotated by one and reversed, a static set's gammas
    // reversed. Each entry: rate, beta, gamma (a static hold's; unused while spinning).
    struct Visit {
      double rate, beta, gamma;
    };
    std::vector<Visit> order;
    for (auto r = test.rates_rad_s.rbegin(); r != test.rates_rad_s.rend(); ++r) {
      std::vector<double> betas(test.beta_rad);
      std::rotate(betas.begin(), betas.begin() + 1, betas.end());
      std::reverse(betas.begin(), betas.end());
      for (double b : betas) {
        if (*r != 0.0) {
          order.push_back({*r, b, 0.0});
          continue;
        }
        for (auto g = test.gamma_rad.rbegin(); g != test.gamma_rad.rend(); ++g) order.push_back({*r, b, *g});
      }
    }
    const double hold_s = static_hold_duration_s(test, reference_rate_rad_s(test, s.centrifuge.rate_rad_s));
    std::vector<Phase>& phases = phases_;
    double t = 0.0, rate = 0.0, beta = order.front().beta, theta = 0.0;
    // The counter platform starts servoed at rest with psi_r = psi0 - theta.
    bool servoed = true;
    double psi0 = 0.7, counter = psi0;  // rad
    const auto add = [&](double duration, double rate1, double beta1, bool dwell,
                         double counter1 = std::numeric_limits<double>::quiet_NaN()) {
      Phase p;
      p.t0 = t;
      p.t1 = t + duration;
      p.rate0 = rate;
      p.rate1 = rate1;
      p.beta0 = beta;
      p.beta1 = beta1;
      p.theta0 = theta;
      // The servo engages when the main axis starts (keeping the counter platform where it is) and releases
      // when it has stopped; an indexed platform moves to counter1.
      if (!servoed && rate1 != 0.0) {
        servoed = true;
        psi0 = counter + theta;
      } else if (servoed && rate == 0.0 && rate1 == 0.0) {
        servoed = false;
        counter = psi0 - theta;
      }
      p.servoed = servoed;
      p.psi0 = psi0;
      p.counter0 = counter;
      p.counter1 = servoed || std::isnan(counter1) ? counter : counter1;  // NaN: the platform stays
      if (!servoed) counter = p.counter1;
      p.dwell = dwell;
      if (dwell)
        p.dwell_index = static_cast<int>(
            std::count_if(phases.begin(), phases.end(), [](const Phase& q) { return q.dwell; }));
      // The drive's angle at the end (without ripple: the ripple's angle is added where it is evaluated).
      theta += rate * duration + (rate1 - rate) * 0.5 * duration;
      if (dwell && imp.ripple != 0.0 && rate != 0.0) {
        const double wr = 2.0 * kPi * imp.ripple_hz;
        theta += rate * imp.ripple * (1.0 - std::cos(wr * duration)) / wr;
      }
      phases.push_back(p);
      t = p.t1;
      rate = rate1;
      beta = beta1;
    };
    add(2.0, 0.0, beta, false);  // at rest
    for (const Visit& v : order) {
      const double drive = v.rate * (1.0 + imp.rate_offset);
      if (drive != rate) add(motion.ramp_s, drive, beta, false);
      if (v.beta != beta) add(motion.move_s, rate, v.beta, false);
      if (v.rate == 0.0) {
        // Stopped: the servo lets go, the counter platform is indexed to psi_r = -gamma (the shorter way
        // round), then the hold.
        if (servoed) add(0.5, 0.0, beta, false);
        const double target = counter + wrap_deg((-v.gamma - counter) * kRadToDeg) * kDegToRad;
        if (target != counter) add(motion.move_s, 0.0, beta, false, target);
        add(test.settle_s + hold_s + motion.extra_dwell_s, 0.0, beta, true);
        continue;
      }
      const double planned = test.revolutions * 2.0 * kPi / std::abs(v.rate);
      add(test.settle_s + planned + motion.extra_dwell_s, rate, beta, true);
    }
    if (rate != 0.0) add(motion.ramp_s, 0.0, beta, false);
  }

  /// The phases in time order (the last ends at duration_s()).
  const std::vector<rig_detail::Phase>& phases() const { return phases_; }
  /// The record's length, s.
  double duration_s() const { return phases_.back().t1; }

  /// The index of the phase that holds time t, s (the first for t < 0, the last from its end on).
  std::size_t phase_at(double t) const {
    const auto it = std::upper_bound(phases_.begin(), phases_.end(), t,
                                     [](double x, const rig_detail::Phase& p) { return x < p.t1; });
    return std::min(static_cast<std::size_t>(it - phases_.begin()), phases_.size() - 1);
  }

  /// The machine's true joints at time t, s, inside phase `p` (phase_at(t)): angles rad, rates rad/s,
  /// accelerations rad/s^2. The ripple rides on a spinning dwell; a move of beta inside the fourth dwell
  /// (RigImperfections::beta_move_in_dwell_deg) is a true move.
  JointState joints(const rig_detail::Phase& p, double t) const {
    const double d = p.t1 - p.t0, tau = t - p.t0, u = tau / d;
    JointState j;
    // Main axis: a smooth ramp of the rate, then the ripple on top while the drive turns.
    const double dr = p.rate1 - p.rate0;
    double w = p.rate0 + dr * rig_detail::step(u);
    double th = p.theta0 + p.rate0 * tau + dr * (0.5 * tau - d / (2.0 * kPi) * std::sin(kPi * u));
    double acc = dr * rig_detail::step_rate(u) / d;
    if (imp_.ripple != 0.0 && p.dwell && p.rate0 != 0.0) {
      const double wr = 2.0 * kPi * imp_.ripple_hz;
      w += p.rate0 * imp_.ripple * std::sin(wr * tau);
      th += p.rate0 * imp_.ripple * (1.0 - std::cos(wr * tau)) / wr;
      acc += p.rate0 * imp_.ripple * wr * std::cos(wr * tau);
    }
    j.main_angle_rad = th;
    j.main_rate_rad_s = w;
    j.main_accel_rad_s2 = acc;
    if (p.servoed) {
      j.counter_angle_rad = p.psi0 - th;
      j.counter_rate_rad_s = -w;
      j.counter_accel_rad_s2 = -acc;
    } else {
      const double dc = p.counter1 - p.counter0;
      j.counter_angle_rad = p.counter0 + dc * rig_detail::step(u);
      j.counter_rate_rad_s = dc * rig_detail::step_rate(u) / d;
      j.counter_accel_rad_s2 =
          dc * 0.5 * kPi * kPi * std::cos(kPi * u) / (d * d) * (u > 0 && u < 1 ? 1.0 : 0.0);
    }
    const double db = p.beta1 - p.beta0;
    j.position_angle_rad = p.beta0 + db * rig_detail::step(u);
    j.position_rate_rad_s = db * rig_detail::step_rate(u) / d;
    j.position_accel_rad_s2 =
        db * 0.5 * kPi * kPi * std::cos(kPi * u) / (d * d) * (u > 0 && u < 1 ? 1.0 : 0.0);
    if (p.dwell && p.dwell_index == 3 && imp_.beta_move_in_dwell_deg != 0.0 && tau >= 0.5) {
      // The platform really moves (and stays): the model sees it too.
      j.position_angle_rad += imp_.beta_move_in_dwell_deg * kDegToRad;
    }
    return j;
  }
  /// The same at any time t, s.
  JointState joints(double t) const { return joints(phases_[phase_at(t)], t); }

 private:
  RigImperfections imp_;
  std::vector<rig_detail::Phase> phases_;
};

/// Calls emit(row) for each row of a rig's record of `s`'s plan, in time order, on RigTrajectory's motion.
inline void rig_rows(const Scenario& s, const RigImperfections& imp, const RigMotion& motion,
                     std::uint64_t seed, const std::function<void(const RigRow&)>& emit) {
  using rig_detail::Phase;
  const CentrifugeModel model = s.model();
  const TestSpec& test = s.test;
  const bool accelerometer = s.sensor_kind == SensorKind::kAccelerometer;
  const RigTrajectory trajectory(s, imp, motion);
  const std::vector<Phase>& phases = trajectory.phases();
  const double t = trajectory.duration_s();

  // The output's noise and the acquisition's imperfections draw from separate streams: a record with and
  // without jitter has the same noise.
  std::mt19937_64 rng(seed), acquisition(seed ^ 0x9e3779b97f4a7c15ULL);
  std::normal_distribution<double> noise(0.0, motion.noise_deg_h);
  const double k1 = s.accelerometer.coefficients[AccelCoefficient::K1];
  AccelerometerNoiseGenerator accelerometer_noise(s.accelerometer.noise, k1, test.sample_rate_hz, seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::bernoulli_distribution toggle(0.5);
  const double fs = test.sample_rate_hz;
  const auto n = static_cast<std::uint64_t>(std::floor(t * fs));
  const auto spike_every = imp.spikes > 0 ? n / static_cast<std::uint64_t>(imp.spikes + 1) : 0;
  const auto quantise = [](double a, double q) { return q > 0 ? q * std::round(a / q) : a; };
  std::size_t pi = 0;
  double jump = 0.0;
  for (std::uint64_t k = 0; k < n; ++k) {
    const double tk = static_cast<double>(k) / fs;  // the uniform clock
    while (pi + 1 < phases.size() && tk >= phases[pi].t1) ++pi;
    const Phase& p = phases[pi];
    const double d = p.t1 - p.t0;
    const JointState j = trajectory.joints(p, tk);
    const double th = j.main_angle_rad;
    double beta_read_offset = 0.0;
    const SensorInputs in = exact_inputs(model, j);
    double y = accelerometer ? accelerometer_noise.next(s.accelerometer.output(in))
                             : gyro_output_deg_h(s.gyro, in.rate_rad_s.x(), in.specific_force_g) + noise(rng);
    if (spike_every > 0 && k % spike_every == spike_every / 2 &&
        k / spike_every <= static_cast<std::uint64_t>(imp.spikes))
      y += accelerometer ? k1 * imp.spike_g : imp.spike_deg_h;
    // The acquisition.
    const double mid = 0.5 * (p.t0 + p.t1);
    if (p.dwell && p.dwell_index == 2 && imp.gap_fraction > 0.0 &&
        std::abs(tk - mid) < 0.5 * imp.gap_fraction * d)
      continue;
    if (p.dwell && p.dwell_index == 4 && imp.clock_jump_s != 0.0 && tk >= mid) jump = imp.clock_jump_s;
    if (p.dwell && p.dwell_index == 1 && imp.beta_glitch_deg != 0.0 && std::abs(tk - mid) < 0.5 / fs)
      beta_read_offset = imp.beta_glitch_deg;
    double stamp = tk + imp.jitter_s * uniform(acquisition);
    if (imp.stamp_resolution_s > 0)
      stamp = imp.stamp_resolution_s * std::round(stamp / imp.stamp_resolution_s);
    RigRow row;
    row.time_s = stamp + jump;
    row.main_angle_deg = quantise(std::fmod(th * kRadToDeg, 360.0), imp.angle_quantum_deg);
    row.counter_angle_deg = quantise(wrap_deg(j.counter_angle_rad * kRadToDeg), imp.angle_quantum_deg);
    double b = j.position_angle_rad * kRadToDeg;
    if (imp.position_count_deg > 0)
      b = imp.position_count_deg *
          (std::floor(b / imp.position_count_deg) + (toggle(acquisition) ? 1.0 : 0.0));
    row.position_angle_deg = b + beta_read_offset;
    row.output = y;
    row.truth = j;
    emit(row);
  }
}

/// The rows of rig_rows() as gyrocal's native record (columns in degrees, time in s; the output column a
/// gyro's, or "accel_g" for an accelerometer's in g).
inline void write_native(std::ostream& out, const std::vector<RigRow>& rows,
                         std::string_view output_column = "gyro_deg_h") {
  out << kRecordMagic << "\n";
  out << "time_s,main_angle_deg,counter_angle_deg,position_angle_deg," << output_column << "\n";
  out.precision(17);
  for (const RigRow& r : rows)
    out << r.time_s << ',' << r.main_angle_deg << ',' << r.counter_angle_deg << ',' << r.position_angle_deg
        << ',' << r.output << '\n';
}

/// The rows as RecordSamples (what the native reader gives back).
inline std::vector<RecordSample> as_samples(const std::vector<RigRow>& rows) {
  std::vector<RecordSample> out;
  out.reserve(rows.size());
  for (const RigRow& r : rows) {
    RecordSample x;
    x.time_s = r.time_s;
    x.main_angle_deg = r.main_angle_deg;
    x.counter_angle_deg = r.counter_angle_deg;
    x.position_angle_deg = r.position_angle_deg;
    x.outputs[0] = r.output;
    out.push_back(x);
  }
  return out;
}

}  // namespace gyrocal::testing
