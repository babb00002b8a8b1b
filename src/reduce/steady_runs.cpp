#include "reducer_state.hpp"

// Steady runs (reduce/reducer_state.hpp): a steady state looked for in the rows, a run started, matched to
// the plan and followed row by row until the machine leaves it; its measured rows go to the dwell's
// accumulator. The per-row path of the reducer.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/plan/positions.hpp"
#include "gyrocal/reduce/feasibility.hpp"

namespace gyrocal {

// The entry of the per-row path: a row of the record, its time checked, taken.
void Reducer::push_unsummarised(const RecordSample& s) {
  State& st = *state_;
  if (st.rows > 0 && !(s.time_s > st.t_last))
    throw Error(fmt::format("{}: time does not increase.", st.at(s.time_s)));
  ++st.rows;
  st.t_last = s.time_s;
  if (st.outputs > 1) st.keep_more_outputs(s);
  st.take(
      Row{s.time_s, s.main_angle_deg, s.counter_angle_deg, s.position_angle_deg, s.outputs[0], st.rows - 1});
}

void Reducer::State::keep_more_outputs(const RecordSample& s) {
  // The oldest row still held: the window's first, a run's first held row, its guard's first (each holds
  // rows in the record's order; between rows nothing else holds one, take() having emptied its queues).
  std::uint64_t oldest = rows - 1;
  if (!window.empty()) oldest = std::min(oldest, window.front().serial);
  if (run) {
    if (!run->held.empty()) oldest = std::min(oldest, run->held.front().serial);
    if (!run->guard.empty()) oldest = std::min(oldest, run->guard.front().u.serial);
  }
  while (more_front < oldest && !more_outputs_of_rows.empty()) {
    more_outputs_of_rows.pop_front();
    ++more_front;
  }
  if (more_outputs_of_rows.empty()) more_front = rows - 1;
  std::array<double, limits::kMaxOutputColumns - 1> more{};
  std::copy_n(s.outputs.begin() + 1, outputs - 1, more.begin());
  more_outputs_of_rows.push_back(more);
}

void Reducer::State::row_outputs(const Row& u, double* values) const {
  if (u.serial < more_front || u.serial - more_front >= more_outputs_of_rows.size())
    throw Error(fmt::format("{}: internal error: the output columns of the row at t = {} s were not kept.",
                            source, u.t));
  values[0] = u.y;
  const auto& more = more_outputs_of_rows[static_cast<std::size_t>(u.serial - more_front)];
  std::copy_n(more.begin(), outputs - 1, values + 1);
}

void Reducer::State::look(const Row& raw) {
  // A reading no encoder writes (a corrupt field) is skipped: the window's lines and unwrapping go on from
  // the last readable row.
  if (unreadable_encoder(raw) != nullptr) [[unlikely]]
    return;
  Row r = raw;
  if (!window.empty()) {
    const Row& p = window.back();
    if (is_gap(r.t - p.t)) {
      window.clear();
    } else {
      r.theta = p.theta + wrap_deg_quick(raw.theta - raw_theta_prev);
      r.psi = p.psi + wrap_deg_quick(raw.psi - raw_psi_prev);
    }
  }
  raw_theta_prev = raw.theta;
  raw_psi_prev = raw.psi;
  window.push_back(r);
  while (window.size() > kMaxWindowRows || window.back().t - window.front().t > 2.0 * options.window_s)
    window.pop_front();
  if (window.back().t - window_tested_at < 0.25 * options.window_s) return;
  // The last window_s of rows.
  auto first = window.end();
  while (first != window.begin() && window.back().t - std::prev(first)->t <= options.window_s) --first;
  if (first == window.begin() || std::distance(first, window.end()) < 8) return;
  window_tested_at = window.back().t;
  Line th, ps;
  fit_lines(first, window.end(), th, ps);
  if (th.max_residual > options.angle_tolerance_deg || ps.max_residual > options.angle_tolerance_deg) return;
  std::vector<double> betas;
  for (auto it = first; it != window.end(); ++it) betas.push_back(it->beta);
  const double beta = median_of(betas);
  for (double b : betas)
    if (std::abs(wrap_deg_quick(b - beta)) > options.beta_tolerance_deg) return;
  if (offset_ramp(th.rate * kDegToRad, ps.rate * kDegToRad)) return;
  // Steady: the run begins at the earliest row before the window that still lies on its lines as closely as
  // the window's own rows do (twice their largest residual, and beta within their spread): the end of a
  // ramp or a move is not taken in.
  double beta_spread = 0.0;
  for (double b : betas) beta_spread = std::max(beta_spread, std::abs(wrap_deg_quick(b - beta)));
  const double th_tol = std::max(2.0 * th.max_residual, 1e-9), ps_tol = std::max(2.0 * ps.max_residual, 1e-9);
  while (first != window.begin()) {
    const Row& q = *std::prev(first);
    if (std::abs(q.theta - th(q.t)) > th_tol || std::abs(q.psi - ps(q.t)) > ps_tol ||
        std::abs(wrap_deg_quick(q.beta - beta)) > beta_spread + 1e-9)
      break;
    --first;
  }
  // A run starts after the start of the one before: a run that ended before accepting a row hands its
  // first row back, and would otherwise start there again, and again (found with encoder counts read as
  // degrees).
  while (first != window.end() && first->t <= last_run_start_s) ++first;
  if (std::distance(first, window.end()) < 8) return;
  start_run(*first, th, ps, beta);
  std::vector<Row> rows_of_run(first, window.end());
  window.clear();
  // follow() unwraps against the run's lines: the rows' readings as the record gave them.
  for (Row& q : rows_of_run) q.theta = wrap_deg_quick(q.theta), q.psi = wrap_deg_quick(q.psi);
  for (const Row& q : rows_of_run) take(q);
}

bool Reducer::State::offset_ramp(double main_rate_rad_s, double counter_rate_rad_s) const {
  bool has_offset = false;
  for (double o : plan.counter_rate_offsets_rad_s)
    if (o != 0.0) has_offset = true;
  if (!has_offset) return false;
  const double tol0 = options.static_rate_tolerance_rad_s;
  const bool main_stopped = std::abs(main_rate_rad_s) < tol0;
  if (main_stopped && std::abs(counter_rate_rad_s) < tol0) return false;  // a static hold
  const double heading = main_rate_rad_s + counter_rate_rad_s;
  for (double r : plan.rates_rad_s) {
    const bool main_at_r =
        r == 0.0 ? main_stopped : std::abs(main_rate_rad_s - r) <= options.rate_tolerance * std::abs(r);
    if (!main_at_r) continue;
    for (double o : plan.counter_rate_offsets_rad_s) {
      if (r == 0.0 && o == 0.0) continue;
      // Within rate_steadiness, the tolerance the run's windows are then held to (a window still holding
      // the ramp's end would start a run whose next window ends it).
      if (std::abs(heading - o) <= options.rate_steadiness * std::max(std::abs(r), std::abs(o))) return false;
    }
    return true;
  }
  return false;
}

void Reducer::State::take(const Row& raw) {
  // Rows handed back while a row is taken (a new run's rows replayed from its start, the rows an ended run
  // held) are taken after it, in order, not by recursion: a record whose runs start and end every few rows
  // (encoder counts read as degrees) nested the calls thousands deep and overflowed the stack.
  if (taking) {
    handed_back.push_back(raw);
    return;
  }
  taking = true;
  take_one(raw);
  for (;;) {
    if (!handed_back.empty()) {
      pending.insert(pending.begin(), handed_back.begin(), handed_back.end());
      handed_back.clear();
    }
    if (pending.empty()) break;
    const Row q = pending.front();
    pending.pop_front();
    take_one(q);
  }
  taking = false;
}

void Reducer::State::take_one(const Row& raw) {
  if (run)
    follow(raw);
  else
    look(raw);
}

void Reducer::State::start_run(const Row& first, const Line& th, const Line& ps, double beta) {
  last_run_start_s = first.t;
  Run r;
  r.start_s = r.end_s = first.t;
  r.last_t_record = r.prev_row_t = r.t_prev = first.t - dt_planned;
  r.theta_prev = th(r.t_prev);
  r.psi_prev = ps(r.t_prev);
  r.rate_theta = th.rate;
  r.rate_psi = ps.rate;
  r.beta_deg = beta;
  r.gamma_deg = wrap_deg_quick(-ps(first.t));
  r.theta_line = th;
  r.psi_line = ps;
  r.block_t0 = first.t;
  run = std::move(r);
}

void Reducer::State::decide(Run& r, double t) {
  r.decided = true;
  r.hold_theta = r.theta_line(t);
  r.hold_psi = r.psi_line(t);
  r.match =
      match_to_plan(plan, options, r.rate_theta * kDegToRad, r.rate_psi * kDegToRad, r.beta_deg, r.gamma_deg);
  r.matched = r.match.why_not.empty();
  if (!r.matched) {
    // The rows that waited for the match belong to no dwell.
    r.quality.settle_rows += r.guard.size();
    r.guard.clear();
    return;
  }
  // A spinning dwell: whole revolutions of gamma, which turns at rate - offset (docs/physics.md section
  // 15).
  const double rate = r.match.planned_rate_rad_s, offset = r.match.planned_counter_rate_offset_rad_s;
  r.planned_duration =
      r.match.is_static ? hold_duration() : plan.revolutions * 2.0 * kPi / std::abs(rate - offset);
  const std::vector<double> gammas =
      r.match.is_static ? std::vector<double>{r.match.gamma_rad} : spinning_gammas(plan);
  r.accs.clear();
  r.accs.reserve(outputs);
  for (std::size_t k = 0; k < outputs; ++k)
    r.accs.emplace_back(options, gammas, r.match.is_static, 1, r.planned_duration, true,
                        heading_sweep_rad_s(rate, offset));
}

void Reducer::State::follow(const Row& raw) {
  Run& r = *run;
  // A gap: the interval from the previous row (accepted or not) is long. Inside the measured part the
  // dwell's clock counts it as one planned interval.
  const bool gap = is_gap(raw.t - r.prev_row_t);
  r.prev_row_t = raw.t;
  const double dt = raw.t - r.last_t_record;
  double offset = r.clock_offset;
  // The measured part begins with the settle time's end (its rows wait in the guard until the run is
  // matched to the plan).
  const bool in_measured_part = r.decided ? r.matched : raw.t >= r.start_s + plan.settle_s;
  if (gap && in_measured_part) offset += dt - dt_planned;
  const double t = raw.t - offset;
  // Each reading is predicted from the last accepted one at the rate of the last window; after a gap the
  // encoders' phase is unknown (a clock jump looks like a gap), so only beta is judged there and the angles
  // continue to within half a turn of the prediction over one planned interval.
  const double step = gap ? dt_planned : t - r.t_prev;
  const double th_pred = r.theta_prev + r.theta_line.rate * step,
               ps_pred = r.psi_prev + r.psi_line.rate * step;
  Row u = raw;
  u.t = t;
  u.theta = th_pred + wrap_deg_quick(raw.theta - th_pred);
  u.psi = ps_pred + wrap_deg_quick(raw.psi - ps_pred);
  const double db = wrap_deg_quick(raw.beta - r.beta_deg);
  Deviations dev;
  dev.beta = std::abs(db);
  if (!gap) dev.angle = std::max(std::abs(u.theta - th_pred), std::abs(u.psi - ps_pred));
  if (r.decided && r.matched && r.match.is_static)
    dev.hold = std::max(std::abs(wrap_deg_quick(u.theta - r.hold_theta)),
                        std::abs(wrap_deg_quick(u.psi - r.hold_psi)));
  std::string off;
  if (const char* encoder = unreadable_encoder(raw)) [[unlikely]]
    off = fmt::format(
        "the {} encoder reads {:g} deg at t = {:.3f} s, beyond any encoder's {:g} deg "
        "(limits::kEncoderAngleDeg)",
        encoder, encoder_reading(raw, encoder), raw.t, limits::kEncoderAngleDeg);
  else if (std::abs(db) > options.beta_tolerance_deg)
    off = fmt::format("beta moves by {:.3g} deg at t = {:.3f} s", db, raw.t);
  else if (!gap && std::abs(u.theta - th_pred) > options.angle_tolerance_deg)
    off = fmt::format("the main axis leaves its steady rate at t = {:.3f} s (its encoder {:.3g} deg off)",
                      raw.t, u.theta - th_pred);
  else if (!gap && std::abs(u.psi - ps_pred) > options.angle_tolerance_deg)
    off = fmt::format(
        "the counter platform leaves its steady rate at t = {:.3f} s (its encoder {:.3g} deg off)", raw.t,
        u.psi - ps_pred);
  else if (dev.hold > options.beta_tolerance_deg) {
    // A static hold: a move that starts slowly stays within angle_tolerance_deg of each last reading;
    // the hold's angles are held, like beta, within beta_tolerance_deg (docs/calibration.md).
    const double dth = wrap_deg_quick(u.theta - r.hold_theta), dps = wrap_deg_quick(u.psi - r.hold_psi);
    off = std::abs(dth) > options.beta_tolerance_deg
              ? fmt::format("the main axis moves by {:.3g} deg at t = {:.3f} s", dth, raw.t)
              : fmt::format("the counter platform moves by {:.3g} deg at t = {:.3f} s", dps, raw.t);
  }
  if (!off.empty()) {
    if (r.held.empty()) r.held_reason = off;
    r.held.push_back(raw);
    if (r.held.size() > static_cast<std::size_t>(options.encoder_glitch_rows))
      end_run(r.held_reason, Ending::kLeft);
    return;
  }
  if (gap) {
    r.block_theta = r.block_psi = LineSums{};
    r.psi_line_valid = false;
  }
  r.theta_prev = u.theta;
  r.psi_prev = u.psi;
  r.t_prev = t;
  if (!r.held.empty()) {
    // Dropped: as encoder glitches inside the measured part; in the settle time they are settle rows.
    (in_measured_part ? r.quality.encoder_glitch_rows : r.quality.settle_rows) += r.held.size();
    r.held.clear();
    r.dropped = true;
  }
  r.clock_offset = offset;
  r.last_t_record = raw.t;
  r.end_s = raw.t;
  ++r.quality.rows;
  // The rate is judged, and the run matched to the plan, before the row is measured (check_rate).
  if (!check_rate(r, u, t, raw.t)) return;
  if (!r.decided && raw.t < r.start_s + plan.settle_s) {
    ++r.quality.settle_rows;
    return;
  }
  if (!r.decided && raw.t >= r.start_s + plan.settle_s + 2.0 * options.window_s) decide(r, t);
  if (r.decided && !r.matched) return;
  r.guard.push_back({u, gap, r.dropped, raw.t, dev});
  r.dropped = false;
  while (!r.guard.empty() && (r.decided ? r.guard.front().t_record < raw.t - options.leave_guard_s ||
                                              r.guard.size() > kMaxGuardRows
                                        : r.guard.size() > kMaxGuardRows)) {
    const Run::Waiting w = r.guard.front();
    r.guard.pop_front();
    if (!r.decided) {
      ++r.quality.settle_rows;
      continue;
    }
    r.steady_dev.widen(w.dev);
    measure(w.u, w.gap, w.dropped, w.t_record);
    if (!run) return;
  }
}

bool Reducer::State::check_rate(Run& r, const Row& u, double t, double t_record) {
  if (r.block_theta.n == 0) {
    r.block_t0 = t;
    r.block_theta0 = u.theta;
    r.block_psi0 = u.psi;
  }
  r.block_theta.add(t - r.block_t0, u.theta - r.block_theta0);
  r.block_psi.add(t - r.block_t0, u.psi - r.block_psi0);
  if (t - r.block_t0 >= options.window_s && r.block_theta.n >= 8) {
    const double rt = r.block_theta.sty() / r.block_theta.stt(), rp = r.block_psi.sty() / r.block_psi.stt();
    // Relative to the main rate; with the main axis stopped, to the platform's (a rate table at main rate
    // 0, docs/physics.md section 15; a static hold: the stopped tolerance).
    const double tol0_deg = options.static_rate_tolerance_rad_s * kRadToDeg;
    const double scale = std::abs(r.rate_theta) >= tol0_deg ? std::abs(r.rate_theta)
                                                            : std::max(std::abs(r.rate_psi), tol0_deg);
    const double change = std::max(std::abs(rt - r.rate_theta), std::abs(rp - r.rate_psi)) / scale;
    // The run is matched to the plan at the first window closing after its settle time that agrees with
    // the window before it: a run may start in the last tenths of a second of a ramp, whose end then
    // bends its first window (matched on it, the run would be refused or end at the next window, and the
    // next run's settle time would start late). Until then the run follows each window's rate.
    bool decide_now = false;
    if (!r.decided) {
      decide_now = change <= options.rate_steadiness && t_record >= r.start_s + plan.settle_s;
      r.rate_theta = rt;
      r.rate_psi = rp;
    } else if (change > options.rate_steadiness) {
      // With both axes about stopped the relative change has no meaning (it is relative to the stopped
      // tolerance): the change is said in rad/s.
      const bool stopped = std::abs(r.rate_theta) < tol0_deg && std::abs(r.rate_psi) < tol0_deg;
      end_run(stopped
                  ? fmt::format("the stopped machine starts to move (its rate changes by {:.3g} rad/s) in "
                                "the window ending at t = {:.3f} s",
                                change * scale * kDegToRad, t_record)
                  : fmt::format("the rate changes by {:.2e} (relative; rate_steadiness {:.0e}) in the window "
                                "ending at t = {:.3f} s",
                                change, options.rate_steadiness, t_record),
              Ending::kLeft);
      return false;
    }
    const auto line = [&](const LineSums& s, double rate, double y0) {
      Line l;
      l.t0 = r.block_t0;
      l.rate = rate;
      l.at = y0 + s.y / s.n - rate * s.t / s.n;
      return l;
    };
    r.theta_line = line(r.block_theta, rt, r.block_theta0);
    r.psi_line = line(r.block_psi, rp, r.block_psi0);
    ++r.psi_line_serial;
    r.psi_line_valid = true;
    if (!r.decided) r.gamma_deg = wrap_deg_quick(-r.psi_line(t));
    r.block_theta = r.block_psi = LineSums{};
    if (decide_now) decide(r, t);
  }
  return true;
}

void Reducer::State::measure(const Row& u, bool gap, bool dropped, double t_record) {
  Run& r = *run;
  // The plan says how long a dwell is: its measured part is [t_first, t_first + planned duration) on the
  // dwell's clock.
  if (r.measuring && u.t >= r.t_first + r.planned_duration - 1e-9) {
    ++r.quality.beyond_planned_rows;
    return;
  }
  if (increments) [[unlikely]] {
    // An increment over an unknown interval (Reducer::set_increments): the row is left out of every column,
    // and the next one measured starts the stretch the gap would have.
    if (gap || u.serial == 0) {
      ++r.quality.increments_dropped;
      r.gap_pending = r.measuring;
      return;
    }
    gap = r.gap_pending;
    r.gap_pending = false;
  }
  if (!r.measuring) {
    r.measuring = true;
    r.t_first = u.t;
    r.theta_first = u.theta;
    r.psi_first = u.psi;
    r.phase_theta.emplace_back();
    r.phase_psi.emplace_back();
    r.phase_rel.emplace_back();
    r.stretches.push_back({u.t, u.t, 0, 0});
    if (!r.match.is_static && r.match.planned_rate_rad_s != 0.0) {
      const double gamma_rate =
          std::abs(r.match.planned_rate_rad_s - r.match.planned_counter_rate_offset_rad_s);
      r.motion.emplace(dt_planned, u.t, u.theta * kDegToRad, r.match.planned_rate_rad_s,
                       kMeasuredKnotRevolutions * 2.0 * kPi / std::max(gamma_rate, 1e-9), r.planned_duration);
      r.motion->begin_phase(u.t);
    }
  } else if (gap || dropped) {
    if (r.stretches.size() >= static_cast<std::size_t>(options.max_stretches_per_dwell)) {
      end_run(
          fmt::format("gaps and dropped rows break it into more than {} stretches (max_stretches_per_dwell) "
                      "by t = {:.3f} s",
                      options.max_stretches_per_dwell, t_record),
          Ending::kStretches);
      return;
    }
    if (gap) {
      ++r.gaps;
      feed->break_revolution(r.accs);
      r.phase_theta.emplace_back();
      r.phase_psi.emplace_back();
      r.phase_rel.emplace_back();
      if (r.motion) r.motion->begin_phase(u.t);
    }
    r.stretches.push_back({u.t, u.t, 0, r.phase_theta.size() - 1});
  }
  StretchSums& st = r.stretches.back();
  if (st.count == 0) st.first = u.t;
  st.last = u.t;
  ++st.count;
  // On the stretch's own grid: the stamps' jitter is the clock's reading error (docs/calibration.md).
  if (r.motion) r.motion->add(st.first + static_cast<double>(st.count - 1) * dt_planned, u.theta * kDegToRad);
  const double tt = u.t - r.t_first;
  const double planned_turn = r.match.planned_rate_rad_s * kRadToDeg * tt;
  const double y_theta = u.theta - r.theta_first - planned_turn;
  if (st.count > 1) {
    const double dy = y_theta - r.prev_y, dtt = tt - r.prev_tt;
    r.diff_yy += dy * dy;
    r.diff_yt += dy * dtt;
    r.diff_tt += dtt * dtt;
    r.diff_n += 1;
  }
  r.prev_y = y_theta;
  r.prev_tt = tt;
  r.phase_theta.back().add(tt, y_theta);
  // The heading (psi_r + theta) turns at the planned counter rate offset (docs/physics.md section 15).
  const double offset_turn = r.match.planned_counter_rate_offset_rad_s * kRadToDeg * tt;
  r.phase_psi.back().add(tt, u.psi - r.psi_first + planned_turn - offset_turn);
  r.phase_rel.back().add(tt, u.psi - r.psi_first + u.theta - r.theta_first - offset_turn);
  r.beta_sum += u.beta;
  ++r.n;
  // The arm angle of the fit's basis from the line of the last window (smooth: a reading quantised to 0.1
  // deg would put its rounding into every basis function), continued from the reading to within half a
  // turn; after a gap, until a window has closed, the reading itself.
  const double psi = r.psi_line_valid ? u.psi + wrap_deg_quick(r.psi_line(u.t) - u.psi) : u.psi;
  if (r.motion) {
    // Recorded for the model terms (Dwell::basis_angle): a piece where the line or its whole turns change.
    // psi - line is a whole number of turns up to rounding: the nearest by a truncating conversion (a
    // call of libm's round a row was 1 % of calibrate's time).
    const double q = r.psi_line_valid ? (psi - r.psi_line(u.t)) * (1.0 / 360.0) : 0.0;
    const double turns = 360.0 * static_cast<double>(static_cast<std::int64_t>(q + (q >= 0.0 ? 0.5 : -0.5)));
    if (!r.psi_line_valid) {
      r.basis.push_back({r.n - 1, u.t, psi * kDegToRad, 0.0});
      r.basis_serial = std::numeric_limits<std::size_t>::max();  // a reading: the next row starts a piece
    } else if (r.basis.empty() || r.basis_serial != r.psi_line_serial || r.basis_turns != turns) {
      r.basis.push_back(
          {r.n - 1, r.psi_line.t0, (r.psi_line.at + turns) * kDegToRad, r.psi_line.rate * kDegToRad});
      r.basis_serial = r.psi_line_serial;
      r.basis_turns = turns;
    }
  }
  if (outputs == 1) {
    feed->add(std::span<DwellAccumulator>(r.accs.data(), 1), u.t, -psi * kDegToRad, &u.y);
  } else {
    double values[limits::kMaxOutputColumns];
    row_outputs(u, values);
    feed->add(std::span<DwellAccumulator>(r.accs.data(), outputs), u.t, -psi * kDegToRad, values);
  }
}

void Reducer::State::end_run(std::string reason, Ending how) {
  if (!run) return;
  if (how == Ending::kRecordEnds) {
    // The record ends while the run waits for two windows to agree: it is matched on its last window, so
    // that a dwell cut short is measured (or refused) as one.
    if (!run->decided && !run->guard.empty()) decide(*run, run->t_prev);
    while (run && run->matched && !run->guard.empty()) {
      const Run::Waiting w = run->guard.front();
      run->guard.pop_front();
      measure(w.u, w.gap, w.dropped, w.t_record);
    }
    if (!run) return;
  }
  // The machine left: the rows waiting in the guard are measured up to the first that lies further from
  // the steady state than twice the measured rows did (the move's onset, found as the run's start is);
  // from there on they are dropped.
  bool onset = how != Ending::kLeft || !run->measuring;
  while (run && !run->guard.empty()) {
    const Run::Waiting w = run->guard.front();
    onset = onset || !w.dev.within(run->steady_dev);
    if (onset) break;
    run->guard.pop_front();
    measure(w.u, w.gap, w.dropped, w.t_record);
  }
  if (!run) return;
  run->guard.for_each([&](const Run::Waiting& w) {
    // Beyond the planned duration they would not have been measured anyway; before the match they are
    // settle rows.
    const bool beyond = run->measuring && w.u.t >= run->t_first + run->planned_duration - 1e-9;
    ++(!run->decided ? run->quality.settle_rows
       : beyond      ? run->quality.beyond_planned_rows
                     : run->quality.before_leaving_rows);
  });
  run->guard.clear();
  // The run's accumulator is moved and read below: the samples handed to the feed go in first.
  feed->sync();
  Run r = std::move(*run);
  run.reset();
  r.quality.ended = std::move(reason);
  r.quality.run_start_s = r.start_s;
  r.quality.run_end_s = r.end_s;
  finish_run(r);
  window.clear();
  window_tested_at = -std::numeric_limits<double>::infinity();
  for (const Row& q : r.held) take(q);
}

}  // namespace gyrocal
