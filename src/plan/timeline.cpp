#include "gyrocal/plan/timeline.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/plan/positions.hpp"

namespace gyrocal {
namespace {

constexpr double kTwoPi = 2.0 * kPi;

struct AngleRate {
  double angle_rad = 0.0;
  double rate_rad_s = 0.0;
  double accel_rad_s2 = 0.0;
};

AngleRate main_at(const MainMotion& m, double t) {
  const double tau = t - m.anchor_time_s;
  return {m.anchor_angle_rad + m.anchor_rate_rad_s * tau + 0.5 * m.accel_rad_s2 * tau * tau,
          m.anchor_rate_rad_s + m.accel_rad_s2 * tau, m.accel_rad_s2};
}

AngleRate platform_at(const PlatformMotion& m, double t) {
  const double tau = t - m.start_time_s;
  if (m.duration_s <= 0.0 || tau >= m.duration_s) return {m.end_angle_rad, 0.0, 0.0};
  if (tau <= 0.0) return {m.start_angle_rad, 0.0, 0.0};
  const double sign = m.end_angle_rad >= m.start_angle_rad ? 1.0 : -1.0;
  const double a = m.accel_rad_s2;
  const double v = m.cruise_rate_rad_s;
  const double accel_time_s = v / a;
  if (tau < accel_time_s) return {m.start_angle_rad + sign * 0.5 * a * tau * tau, sign * a * tau, sign * a};
  if (tau < m.duration_s - accel_time_s) {
    return {m.start_angle_rad + sign * (0.5 * v * accel_time_s + v * (tau - accel_time_s)), sign * v, 0.0};
  }
  // Decelerating: measured from the end, so that the move ends exactly on end_angle_rad.
  const double left_s = m.duration_s - tau;
  return {m.end_angle_rad - sign * 0.5 * a * left_s * left_s, sign * a * left_s, -sign * a};
}

/// Shortest duration of a trapezoidal move of |distance| under the limits, s.
double shortest_move_s(double distance_rad, const MotionLimits& limits) {
  const double d = std::abs(distance_rad);
  const double v = limits.platform_rate_rad_s;
  const double a = limits.platform_accel_rad_s2;
  if (d >= v * v / a) return d / v + v / a;
  return 2.0 * std::sqrt(d / a);  // triangular: the top rate is not reached
}

/// The move from `from` to `to` starting at t0 over duration_s (>= shortest_move_s of the distance).
PlatformMotion make_move(double t0, double from, double to, double duration_s, const MotionLimits& limits) {
  const double d = std::abs(to - from);
  const double a = limits.platform_accel_rad_s2;
  // Cruise rate v of a trapezoid of distance d, duration T: v (T - v/a) = d, the smaller root, written
  // without cancellation. At the shortest duration the root is double (clamped against rounding).
  const double root = std::sqrt(std::max(0.0, duration_s * duration_s - 4.0 * d / a));
  const double v = std::min(2.0 * d / (duration_s + root), limits.platform_rate_rad_s);
  return {t0, from, to, duration_s, a, v};
}

/// `angle` plus the multiple of 2 pi that brings it nearest to `near`.
double nearest_branch(double angle_rad, double near_rad) {
  return angle_rad + kTwoPi * std::round((near_rad - angle_rad) / kTwoPi);
}

void check(bool ok, std::string_view what) {
  if (!ok) throw Error(fmt::format("Cannot plan the test: {}.", what));
}

void validate(const TestSpec& test, const CentrifugeModel& model, const MotionLimits& limits) {
  check(std::isfinite(test.sample_rate_hz) && test.sample_rate_hz > 0.0,
        "[test] sample_rate_hz must be a finite number > 0");
  check(test.revolutions >= 1, "[test] revolutions must be at least 1");
  check(std::isfinite(test.settle_s) && test.settle_s >= 0.0, "[test] settle_s must be a finite number >= 0");
  check(!test.rates_rad_s.empty(), "[test] rates_rad_s is empty");
  check(!test.beta_rad.empty(), "[test] beta_deg is empty");
  check(!test.gamma_rad.empty(), "[test] gamma_deg is empty");
  for (const double v : test.rates_rad_s)
    check(std::isfinite(v), "[test] rates_rad_s holds a non-finite value");
  for (const double v : test.beta_rad) check(std::isfinite(v), "[test] beta_deg holds a non-finite value");
  for (const double v : test.gamma_rad) check(std::isfinite(v), "[test] gamma_deg holds a non-finite value");
  check(!test.counter_rate_offsets_rad_s.empty(), "[test] counter_rate_offsets_rad_s is empty");
  for (const double o : test.counter_rate_offsets_rad_s) {
    check(std::isfinite(o), "[test] counter_rate_offsets_rad_s holds a non-finite value");
    for (const double r : test.rates_rad_s)
      check(
          o == 0.0 || r != o,
          fmt::format("[test] counter_rate_offsets_rad_s holds {} rad/s, equal to a rate: the platform would "
                      "turn with the arm and gamma would stand still",
                      o));
  }
  check(limits.main_accel_rad_s2 > 0.0 && limits.platform_rate_rad_s > 0.0 &&
            limits.platform_accel_rad_s2 > 0.0,
        "the motion limits must be > 0");
  const double mismatch = model.errors().counter_rate_mismatch_rad_s;
  check(std::isfinite(mismatch) && std::abs(mismatch) < limits.platform_rate_rad_s,
        fmt::format("|counter_rate_mismatch_rad_s| must be below the platform's top rate of {} rad/s",
                    limits.platform_rate_rad_s));
}

/// Appends segments while tracking the joints' current motion.
class Builder {
 public:
  Builder(const TestSpec& test, const CentrifugeModel& model, const MotionLimits& limits)
      : test_(test), limits_(limits) {
    timeline_.psi0_rad = model.geometry().heading_rad;
    timeline_.counter_rate_mismatch_rad_s = model.errors().counter_rate_mismatch_rad_s;
    timeline_.reference_rate_rad_s = reference_rate_rad_s(test, model.geometry().rate_rad_s);
    check(std::isfinite(test.static_hold_s) && test.static_hold_s >= 0.0,
          "[test] static_hold_s must be a finite number >= 0");
    check(
        test.static_hold_s > 0.0 ||
            (std::isfinite(timeline_.reference_rate_rad_s) && timeline_.reference_rate_rad_s != 0.0),
        "a test with only rate 0 needs [test] static_hold_s or a non-zero [centrifuge] rate_rad_s to set the "
        "hold time");
    timeline_.hold_s = static_hold_duration_s(test, timeline_.reference_rate_rad_s);

    // The test starts in its first position: spinning, or stopped and indexed to the first gamma.
    rate_ = test.rates_rad_s.front();
    offset_ = test.counter_rate_offsets_rad_s.front();
    main_ = {0.0, model.geometry().initial_main_angle_rad, rate_, 0.0};
    offset_motion_ = {0.0, 0.0, offset_, 0.0};
    position_ = PlatformMotion::hold(test.beta_rad.front());
    servoed_ = rate_ != 0.0 || offset_ != 0.0;
    counter_ = PlatformMotion::hold(-test.gamma_rad.front());
  }

  Timeline build() {
    const std::vector<Position> positions = test_positions(test_);
    const std::size_t n_offset = test_.counter_rate_offsets_rad_s.size();
    const std::size_t n_beta = test_.beta_rad.size();
    const std::size_t n_gamma = test_.gamma_rad.size();
    std::size_t first = 0;  // the first position of each (rate, offset, beta)
    for (std::size_t i = 0; i < test_.rates_rad_s.size(); ++i) {
      const double rate = test_.rates_rad_s[i];
      for (std::size_t o = 0; o < n_offset; ++o) {
        const double offset = test_.counter_rate_offsets_rad_s[o];
        for (std::size_t j = 0; j < n_beta; ++j) {
          const double beta = test_.beta_rad[j];
          if (rate != 0.0 || offset != 0.0) {
            transition(rate, offset, beta);
            add(SegmentKind::kSettle, test_.settle_s);
            // Whole revolutions of gamma, which turns at rate - offset (docs/physics.md section 15).
            measure(SegmentKind::kDwell, revolutions_s(rate - offset), positions[first], 0.0);
            first += spinning_gammas(test_).size();
            continue;
          }
          for (std::size_t k = 0; k < n_gamma; ++k) {
            transition(rate, offset, beta);
            index_counter(-test_.gamma_rad[k]);
            add(SegmentKind::kSettle, test_.settle_s);
            measure(SegmentKind::kHold, timeline_.hold_s, positions[first + k], test_.gamma_rad[k]);
          }
          first += n_gamma;
        }
      }
    }
    timeline_.duration_s = t_;
    return std::move(timeline_);
  }

 private:
  double revolutions_s(double rate) const { return test_.revolutions * kTwoPi / std::abs(rate); }

  /// The counter platform's servo law at t (docs/physics.md section 3), on the current branch.
  double servo_angle(double t) const {
    return -main_at(main_, t).angle_rad + timeline_.psi0_rad + timeline_.counter_rate_mismatch_rad_s * t +
           main_at(offset_motion_, t).angle_rad + servo_offset_rad_;
  }

  double counter_angle_now() const {
    return servoed_ ? servo_angle(t_) : platform_at(counter_, t_).angle_rad;
  }

  void add(SegmentKind kind, double duration_s) {
    if (!(duration_s > 0.0)) return;
    timeline_.segments.push_back(
        {kind, t_, t_ + duration_s, main_, position_, servoed_, servo_offset_rad_, offset_motion_, counter_});
    t_ += duration_s;
  }

  void measure(SegmentKind kind, double duration_s, const Position& position, double gamma_rad) {
    timeline_.measurements.push_back({kind, position.index, position.rate_rad_s, position.beta_rad, gamma_rad,
                                      position.counter_rate_offset_rad_s, t_, t_ + duration_s});
    add(kind, duration_s);
  }

  void transition(double rate, double offset, double beta) {
    if (beta != position_.end_angle_rad) {
      const double from = position_.end_angle_rad;
      position_ = make_move(t_, from, beta, shortest_move_s(beta - from, limits_), limits_);
      add(SegmentKind::kPositionMove, position_.duration_s);
      position_ = PlatformMotion::hold(beta);
    }
    if (rate == rate_ && offset == offset_) return;
    if (!servoed_) engage_counter();
    if (rate != rate_) ramp(SegmentKind::kMainRamp, main_, rate_, rate, limits_.main_accel_rad_s2);
    // docs/physics.md section 15: the counter platform changes its rate offset as a platform accelerates;
    // phi and its rate stay continuous.
    if (offset != offset_)
      ramp(SegmentKind::kOffsetRamp, offset_motion_, offset_, offset, limits_.platform_accel_rad_s2);
  }

  /// A ramp of `motion` from rate `from` to `to` at `accel` (rad/s^2): its angle and rate continuous; `from`
  /// becomes `to`.
  void ramp(SegmentKind kind, MainMotion& motion, double& from, double to, double accel) {
    motion = {t_, main_at(motion, t_).angle_rad, from, std::copysign(accel, to - from)};
    add(kind, std::abs(to - from) / accel);
    motion = {t_, main_at(motion, t_).angle_rad, to, 0.0};
    from = to;
  }

  /// From rest: the counter platform moves onto its servo law (which drifts at delta omega meanwhile).
  void engage_counter() {
    const double from = platform_at(counter_, t_).angle_rad;
    servo_offset_rad_ = 0.0;
    servo_offset_rad_ = kTwoPi * std::round((from - servo_angle(t_)) / kTwoPi);  // the nearest branch
    // The target moves by delta omega * T during the move of duration T; T is the shortest duration for the
    // largest distance it can then have, |d0| + |delta omega| T_max, with T_max an upper bound of that
    // duration (shortest_move_s(d) <= d/v + v/a), so that the limits hold.
    const double d0 = std::abs(servo_angle(t_) - from);
    const double v = limits_.platform_rate_rad_s;
    const double mismatch = std::abs(timeline_.counter_rate_mismatch_rad_s);
    const double t_max = (d0 / v + v / limits_.platform_accel_rad_s2) / (1.0 - mismatch / v);
    const double duration_s = shortest_move_s(d0 + mismatch * t_max, limits_);
    counter_ = make_move(t_, from, servo_angle(t_ + duration_s), duration_s, limits_);
    servoed_ = false;
    add(SegmentKind::kCounterMove, duration_s);
    servoed_ = true;
  }

  /// Stopped: the counter platform turns the shortest way to psi_r = target (modulo 2 pi) and holds it.
  void index_counter(double target_rad) {
    const double from = counter_angle_now();
    const double to = nearest_branch(target_rad, from);
    if (!servoed_ && to == from) return;
    counter_ = make_move(t_, from, to, shortest_move_s(to - from, limits_), limits_);
    servoed_ = false;
    add(SegmentKind::kCounterMove, counter_.duration_s);
    counter_ = PlatformMotion::hold(to);
  }

  const TestSpec& test_;
  MotionLimits limits_;
  Timeline timeline_;
  double t_ = 0.0;
  double rate_ = 0.0;
  double offset_ = 0.0;  ///< the counter rate offset commanded now, rad/s
  MainMotion main_;
  MainMotion offset_motion_;  ///< phi(t), the servo's integral of the offset
  PlatformMotion position_;
  bool servoed_ = true;
  double servo_offset_rad_ = 0.0;
  PlatformMotion counter_;
};

}  // namespace

PlatformMotion PlatformMotion::hold(double angle_rad) {
  return {0.0, angle_rad, angle_rad, 0.0, 0.0, 0.0};
}

Timeline make_timeline(const TestSpec& test, const CentrifugeModel& model, const MotionLimits& limits) {
  validate(test, model, limits);
  return Builder(test, model, limits).build();
}

JointState joint_state_at(const Timeline& timeline, double time_s) {
  const double t = std::clamp(time_s, 0.0, timeline.duration_s);
  const auto after = std::upper_bound(timeline.segments.begin(), timeline.segments.end(), t,
                                      [](double value, const Segment& s) { return value < s.start_s; });
  const Segment& s = *(after == timeline.segments.begin() ? after : after - 1);

  const AngleRate main = main_at(s.main, t);
  const AngleRate position = platform_at(s.position, t);
  AngleRate counter;
  if (s.counter_servoed) {
    const AngleRate phi = main_at(s.counter_offset, t);
    counter = {-main.angle_rad + timeline.psi0_rad + timeline.counter_rate_mismatch_rad_s * t +
                   phi.angle_rad + s.counter_servo_offset_rad,
               -main.rate_rad_s + timeline.counter_rate_mismatch_rad_s + phi.rate_rad_s,
               -main.accel_rad_s2 + phi.accel_rad_s2};
  } else {
    counter = platform_at(s.counter, t);
  }
  JointState j;
  j.main_angle_rad = main.angle_rad;
  j.main_rate_rad_s = main.rate_rad_s;
  j.main_accel_rad_s2 = main.accel_rad_s2;
  j.counter_angle_rad = counter.angle_rad;
  j.counter_rate_rad_s = counter.rate_rad_s;
  j.counter_accel_rad_s2 = counter.accel_rad_s2;
  j.position_angle_rad = position.angle_rad;
  j.position_rate_rad_s = position.rate_rad_s;
  j.position_accel_rad_s2 = position.accel_rad_s2;
  return j;
}

std::uint64_t sample_count(const Timeline& timeline, double sample_rate_hz) {
  // Start from the product and settle the rounding against the exact test k / fs < T used for t_k.
  auto n = static_cast<std::uint64_t>(std::max(0.0, std::ceil(timeline.duration_s * sample_rate_hz)));
  while (n > 0 && static_cast<double>(n - 1) / sample_rate_hz >= timeline.duration_s) --n;
  while (static_cast<double>(n) / sample_rate_hz < timeline.duration_s) ++n;
  return n;
}

}  // namespace gyrocal
