#pragma once
// The test timeline: how the three joints move over the whole test (configuration section [test]),
// as an ordered list of segments covering [0, duration) with no jump in any angle or in the main rate.
//
// For each rate of test.rates_rad_s, for each counter rate offset of test.counter_rate_offsets_rad_s
// (docs/physics.md section 15), for each beta of test.beta_rad:
//   spinning (rate != 0 or offset != 0): [transition] settle, dwell of `revolutions` whole revolutions of
//                         gamma, which turns at rate - offset (duration revolutions * 2 pi / |rate - offset|;
//                         with offset 0 whole main-axis revolutions); at rate 0 a plain rate table;
//   stopped (rate == 0):  for each gamma of test.gamma_rad: [transition] settle, hold (duration
//                         revolutions * 2 pi / |reference rate|), the counter platform at psi_r = -gamma.
// The test starts at t = 0 at the first rate, beta and (stopped) gamma with no transition, so that in the
// first spinning dwell theta = theta0 + omega t and psi_r = -theta + psi0 + delta_omega t (docs/physics.md
// section 3) hold exactly as written. A transition holds only the moves that something changes, in this
// order:
//   1. position move: beta turns to the new value (by the configured difference, not modulo 2 pi);
//   2. counter engage (from rest only): the counter platform moves back onto its servo law;
//   3. main ramp: the main axis changes rate at a constant acceleration, theta and d theta/dt continuous;
//   4. offset ramp: the counter platform's rate offset changes at the platforms' acceleration, its angle and
//      rate continuous;
//   5. counter index (stopped only): the counter platform turns the shortest way to psi_r = -gamma.
// While the main axis turns or is servoed, the counter platform follows psi_r = -theta(t) + psi0 +
// delta_omega t + phi(t) + 2 pi m (m an integer, fixed at each engagement; t global), phi the integral of
// the commanded offset (Segment::counter_offset; zero in a plain test). Platform moves follow a
// trapezoidal rate profile (constant acceleration, cruise, constant deceleration; start and end at rest).
// With the main axis stopped the counter platform holds its index exactly (the servo's delta_omega does not
// act), so its rate steps by delta_omega where the servo lets go or takes over; theta, its rate, beta and
// its rate are continuous everywhere.
#include <cstdint>
#include <vector>

#include "gyrocal/core/units.hpp"
#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/plan/test_spec.hpp"

namespace gyrocal {

/// How fast the machine moves between measurements. Defaults: a 1 rad/s^2 main-axis ramp (9.9 rad/s in
/// 9.9 s); platform moves at up to 20 deg/s with 20 deg/s^2 (a 180 deg turn takes 10 s).
struct MotionLimits {
  double main_accel_rad_s2 = 1.0;                   ///< main-axis acceleration of a ramp, rad/s^2 (> 0)
  double platform_rate_rad_s = 20.0 * kDegToRad;    ///< position and counter platforms' top rate, rad/s (> 0)
  double platform_accel_rad_s2 = 20.0 * kDegToRad;  ///< their acceleration, rad/s^2 (> 0)
};

/// What a segment of the timeline is for.
enum class SegmentKind {
  kSettle,        ///< steady, discarded: after each transition (and at the start)
  kDwell,         ///< measurement: whole revolutions of the main axis at a steady rate
  kHold,          ///< measurement: main axis stopped, counter platform indexed to one gamma
  kPositionMove,  ///< the position platform turns to a new beta
  kCounterMove,   ///< the counter platform indexes (stopped) or moves back onto its servo law
  kMainRamp,      ///< the main axis changes rate
  kOffsetRamp,    ///< the counter platform's rate offset changes (docs/physics.md section 15)
};

/// A platform's angle over a segment: a move from start_angle_rad to end_angle_rad with a trapezoidal
/// rate profile of top rate cruise_rate_rad_s and acceleration accel_rad_s2, over duration_s from
/// start_time_s; at rest at end_angle_rad afterwards. start == end (duration 0) is a hold.
struct PlatformMotion {
  double start_time_s = 0.0;
  double start_angle_rad = 0.0;
  double end_angle_rad = 0.0;
  double duration_s = 0.0;
  double accel_rad_s2 = 0.0;       ///< magnitude
  double cruise_rate_rad_s = 0.0;  ///< magnitude; at most the limit's top rate

  /// A platform at rest at angle_rad.
  static PlatformMotion hold(double angle_rad);
};

/// The main axis over a segment: theta(t) = anchor_angle + anchor_rate (t - anchor_time)
/// + accel (t - anchor_time)^2 / 2. Steady stretches share one anchor, so that no rounding accumulates
/// across them (the first stretch's anchor is t = 0, theta0).
struct MainMotion {
  double anchor_time_s = 0.0;
  double anchor_angle_rad = 0.0;
  double anchor_rate_rad_s = 0.0;
  double accel_rad_s2 = 0.0;
};

/// One segment [start_s, end_s) of the timeline.
struct Segment {
  SegmentKind kind = SegmentKind::kSettle;
  double start_s = 0.0;
  double end_s = 0.0;
  MainMotion main;
  PlatformMotion position;
  /// true: psi_r = -theta(t) + psi0 + delta_omega t + counter_servo_offset_rad; false: `counter` moves it.
  bool counter_servoed = true;
  double counter_servo_offset_rad = 0.0;  ///< 2 pi m
  /// phi(t), the servo law's integral of the commanded rate offset (docs/physics.md section 15), rad, with
  /// the same form as the main axis' motion: constant rate in a dwell, constant acceleration in a ramp.
  MainMotion counter_offset;
  PlatformMotion counter;
};

/// A measurement interval: a spinning dwell or a stopped hold, in the order of the test.
struct MeasurementInterval {
  SegmentKind kind = SegmentKind::kDwell;  ///< kDwell or kHold
  /// Position numbering (plan/positions.hpp, 1-based): a hold's own position; for a dwell, the position of
  /// its (rate, beta) and the first gamma: the dwell covers positions [position_index, position_index +
  /// n_gamma).
  int position_index = 0;
  double rate_rad_s = 0.0;  ///< configured main rate, rad/s (0 for a hold)
  double beta_rad = 0.0;    ///< configured position-platform angle, rad
  double gamma_rad = 0.0;   ///< hold: the configured gamma, rad (psi_r = -gamma modulo 2 pi); dwell: 0
  double counter_rate_offset_rad_s = 0.0;  ///< the dwell's commanded counter rate offset, rad/s
  double start_s = 0.0;                    ///< interval [start_s, end_s), s since the start of the test
  double end_s = 0.0;
};

/// The whole test.
struct Timeline {
  std::vector<Segment> segments;  ///< contiguous, ordered, covering [0, duration_s)
  std::vector<MeasurementInterval> measurements;
  double duration_s = 0.0;
  /// The rate that sets a hold's duration: the first non-zero rate of the test, or the centrifuge's
  /// rate_rad_s when the test has none, rad/s.
  double reference_rate_rad_s = 0.0;
  double hold_s = 0.0;    ///< duration of each hold, s: revolutions * 2 pi / |reference rate|
  double psi0_rad = 0.0;  ///< heading psi0 of the servo law, rad
  double counter_rate_mismatch_rad_s = 0.0;  ///< delta omega of the servo law, rad/s
};

/// Builds the timeline of `test` on `model` (theta0, psi0, delta omega and rate_rad_s from the model).
/// Throws Error for an empty list of rates, betas or gammas, a non-finite value, revolutions < 1,
/// settle_s < 0, no non-zero reference rate, non-positive limits, or |delta omega| not below the
/// platforms' top rate (the counter platform could not catch its servo law).
Timeline make_timeline(const TestSpec& test, const CentrifugeModel& model, const MotionLimits& limits = {});

/// The joints at time t (s since the start of the test; clamped to [0, duration]): angles (rad), rates
/// (rad/s) and accelerations (rad/s^2), exact for the segment's profiles. Angles are unwrapped.
/// A non-zero offset needs |rate - offset| of a dwell not 0 (gamma must turn); make_timeline refuses it.
JointState joint_state_at(const Timeline& timeline, double time_s);

/// Number of samples k >= 0 with k / sample_rate_hz < duration_s.
std::uint64_t sample_count(const Timeline& timeline, double sample_rate_hz);

}  // namespace gyrocal
