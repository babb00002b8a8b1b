#include "gyrocal/reduce/reducer.hpp"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <string_view>
#include <thread>
#include <tuple>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/plan/positions.hpp"
#include "gyrocal/reduce/accumulator_feed.hpp"
#include "gyrocal/reduce/feasibility.hpp"
#include "gyrocal/reduce/record_summary.hpp"

namespace gyrocal {
namespace {

/// A first-in first-out queue on one growing ring of slots: std::deque allocates a block every few elements
/// of a large type (four of Run::Waiting), and the guard pushes and pops every row of a record.
template <class T>
class RingQueue {
 public:
  bool empty() const { return size_ == 0; }
  std::size_t size() const { return size_; }
  T& front() { return slots_[head_]; }
  void push_back(const T& x) {
    if (size_ == slots_.size()) grow();
    slots_[(head_ + size_) & (slots_.size() - 1)] = x;
    ++size_;
  }
  void pop_front() {
    head_ = (head_ + 1) & (slots_.size() - 1);
    --size_;
  }
  void clear() { head_ = size_ = 0; }
  /// Calls f on each element, first to last.
  template <class F>
  void for_each(F f) const {
    for (std::size_t i = 0; i < size_; ++i) f(slots_[(head_ + i) & (slots_.size() - 1)]);
  }

 private:
  void grow() {
    std::vector<T> bigger(std::max<std::size_t>(64, 2 * slots_.size()));
    for (std::size_t i = 0; i < size_; ++i) bigger[i] = slots_[(head_ + i) & (slots_.size() - 1)];
    slots_.swap(bigger);
    head_ = 0;
  }
  std::vector<T> slots_;  // a power of two of them
  std::size_t head_ = 0, size_ = 0;
};

/// Straight-line fit of y against t, streaming, on deviations from a planned line (well conditioned).
struct LineSums {
  double n = 0, t = 0, tt = 0, y = 0, ty = 0, yy = 0;
  void add(double ti, double yi) {
    n += 1;
    t += ti;
    tt += ti * ti;
    y += yi;
    ty += ti * yi;
    yy += yi * yi;
  }
  double stt() const { return tt - t * t / n; }
  double sty() const { return ty - t * y / n; }
  double syy() const { return yy - y * y / n; }
};

/// One row as the reducer sees it: the encoders unwrapped (deg) where a run or a window has a phase for them.
struct Row {
  double t = 0.0;
  double theta = 0.0, psi = 0.0, beta = 0.0;  // deg
  double y = 0.0;                             // gyro output, deg/h
};

/// The encoder of a row's first reading (main, counter, position) that no encoder writes: beyond
/// limits::kEncoderAngleDeg in magnitude, or not a number; nullptr when all three are readings. Such a value
/// cannot be wrapped onto a turn (1e308 lies nowhere on it): it is a glitch, never a reading on the line.
const char* unreadable_encoder(const Row& r) {
  constexpr double kMax = limits::kEncoderAngleDeg;
  if (std::abs(r.theta) <= kMax && std::abs(r.psi) <= kMax && std::abs(r.beta) <= kMax) [[likely]]
    return nullptr;
  return !(std::abs(r.theta) <= kMax) ? "main" : !(std::abs(r.psi) <= kMax) ? "counter" : "position";
}

/// The reading of `encoder` ("main", "counter" or "position") in r.
double encoder_reading(const Row& r, std::string_view encoder) {
  return encoder == "main" ? r.theta : encoder == "counter" ? r.psi : r.beta;
}

/// A line angle(t) = at + rate * (t - t0), deg and deg/s, with the largest residual of the rows it was
/// fitted to.
struct Line {
  double t0 = 0.0, at = 0.0, rate = 0.0, max_residual = 0.0;
  double operator()(double t) const { return at + rate * (t - t0); }
};

/// Least-squares lines of theta and psi over rows [first, last) (deviations from the first row).
template <class It>
void fit_lines(It first, It last, Line& theta, Line& psi) {
  LineSums a, b;
  const Row& r0 = *first;
  for (It it = first; it != last; ++it) {
    a.add(it->t - r0.t, it->theta - r0.theta);
    b.add(it->t - r0.t, it->psi - r0.psi);
  }
  const auto make = [&](const LineSums& s, double y0) {
    Line l;
    l.t0 = r0.t;
    l.rate = s.stt() > 0 ? s.sty() / s.stt() : 0.0;
    l.at = y0 + s.y / s.n - l.rate * s.t / s.n;
    return l;
  };
  theta = make(a, r0.theta);
  psi = make(b, r0.psi);
  for (It it = first; it != last; ++it) {
    theta.max_residual = std::max(theta.max_residual, std::abs(it->theta - theta(it->t)));
    psi.max_residual = std::max(psi.max_residual, std::abs(it->psi - psi(it->t)));
  }
}

/// The median of v (reorders v).
double median_of(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// The reducer's warnings in the order they arise, those of one kind aggregated (issue 29): a record that
/// repeats its test a thousand times would otherwise give a line per dwell. Up to kWarningsPerKind warnings
/// of a kind are given as they are; beyond that the kind's warnings become one line, the first in full, then
/// their count and the places of the next few. Memory is bounded by the kinds, whatever the record's length.
class WarningLog {
 public:
  /// Given as they are up to this many of a kind; more are summarised in one line.
  static constexpr std::size_t kWarningsPerKind = 3;
  /// A summary names the places of this many warnings after its first.
  static constexpr std::size_t kPlacesShown = 3;

  /// A warning of `kind` (a short tag, e.g. "outliers"): its sentence and its place in the record (e.g.
  /// "the dwell at 9.9 rad/s, beta 0.0000 deg at t = 12.345 s"), for a summary.
  void add(std::string_view kind, std::string message, std::string place) {
    auto it = std::find_if(kinds_.begin(), kinds_.end(), [&](const Kind& k) { return k.name == kind; });
    if (it == kinds_.end()) {
      kinds_.push_back({std::string(kind), 0, {}, {}});
      it = std::prev(kinds_.end());
    }
    ++it->count;
    if (it->messages.size() < kWarningsPerKind) {
      order_.emplace_back(static_cast<std::size_t>(it - kinds_.begin()), it->messages.size());
      it->messages.push_back(std::move(message));
    }
    if (it->places.size() < kPlacesShown + 1) it->places.push_back(std::move(place));
  }
  /// Warnings added so far, of every kind.
  std::size_t count() const {
    std::size_t n = 0;
    for (const Kind& k : kinds_) n += k.count;
    return n;
  }
  /// The lines, in the order of the warnings they stand for: a kind with more than kWarningsPerKind
  /// warnings as one line where its first warning was.
  std::vector<std::string> lines() const {
    std::vector<std::string> out;
    for (const auto& [kind, index] : order_) {
      const Kind& k = kinds_[kind];
      if (k.count <= kWarningsPerKind) {
        out.push_back(k.messages[index]);
      } else if (index == 0) {
        std::string places;
        for (std::size_t i = 1; i < k.places.size(); ++i) places += (i > 1 ? "; " : "") + k.places[i];
        out.push_back(fmt::format("{} The same warning {} more times ({} in all): {}{}", k.messages[0],
                                  k.count - 1, k.count, places, k.count > k.places.size() ? "; …" : "."));
      }
    }
    return out;
  }

 private:
  struct Kind {
    std::string name;
    std::size_t count = 0;
    std::vector<std::string> messages;  ///< the first kWarningsPerKind
    std::vector<std::string> places;    ///< the first kPlacesShown + 1
  };
  std::vector<Kind> kinds_;
  /// (kind, message) of the messages kept, in order.
  std::vector<std::pair<std::size_t, std::size_t>> order_;
};

/// The key of a dwell in the plan: rate, counter rate offset (docs/physics.md section 15), beta and a static
/// hold's gamma. A record holds one dwell a key; of repeats the longest is used.
using DwellKey = std::tuple<double, double, double, double>;
DwellKey dwell_key(const Dwell& d) {
  return {d.planned_rate_rad_s, d.planned_counter_rate_offset_rad_s, d.beta_rad,
          d.is_static ? d.gammas_rad[0] : 0.0};
}

/// Steady runs that gave no dwell are kept, the longest first, up to this many (bounded memory).
constexpr std::size_t kRejectedKept = 256;
/// The window of rows searched for a steady state never holds more than this many rows.
constexpr std::size_t kMaxWindowRows = std::size_t{1} << 16;
/// The rows waiting ReduceOptions::leave_guard_s before they are measured never exceed this many (15 MB; at
/// 1 MHz the guard is then 0.26 s).
constexpr std::size_t kMaxGuardRows = std::size_t{1} << 18;

/// A stretch being measured, and the phase (encoder line intercepts) it shares with others until a gap.
struct StretchSums {
  double first = 0.0, last = 0.0;
  std::size_t count = 0;
  std::size_t phase = 0;
};

/// How far a row lies from its run's steady state, deg: beta from the run's, the main and counter encoders
/// from their prediction (the last row's reading advanced at the last window's rate), and a static hold's
/// angles from the hold's.
struct Deviations {
  double beta = 0.0, angle = 0.0, hold = 0.0;
  void widen(const Deviations& o) {
    beta = std::max(beta, o.beta);
    angle = std::max(angle, o.angle);
    hold = std::max(hold, o.hold);
  }
  /// Within twice `steady`'s (and 1e-9 deg): a row as close to the steady state as the measured rows were.
  bool within(const Deviations& steady) const {
    return beta <= 2.0 * steady.beta + 1e-9 && angle <= 2.0 * steady.angle + 1e-9 &&
           hold <= 2.0 * steady.hold + 1e-9;
  }
};

/// The run in progress: consecutive rows at one steady state of the machine.
struct Run {
  PlanMatch match;
  bool decided = false;  // matched to the plan (at the end of the settle time)
  bool matched = false;
  double start_s = 0.0, end_s = 0.0;  // record time
  double planned_duration = 0.0;
  // The reference state from the window that established the run.
  double rate_theta = 0.0, rate_psi = 0.0;  // deg/s
  double beta_deg = 0.0, gamma_deg = 0.0;
  // The local lines the next rows are checked against (the last window's), on the run's clock.
  Line theta_line, psi_line;
  std::size_t psi_line_serial = 0;  // counts the lines psi_line has held
  bool psi_line_valid = true;  // psi_line holds the phase (false after a gap until the next window closes)
  // The current window of the rate check.
  LineSums block_theta, block_psi;
  double block_t0 = 0.0, block_theta0 = 0.0, block_psi0 = 0.0;
  // The run's clock: record time minus the gaps (each counted as one planned interval) since the
  // measurement began.
  double clock_offset = 0.0;
  double last_t_record = 0.0;                             // the last accepted row
  double prev_row_t = 0.0;                                // the last row seen, accepted or not
  double t_prev = 0.0, theta_prev = 0.0, psi_prev = 0.0;  // the last accepted row, run's clock, unwrapped
  std::vector<Row> held;  // rows off the line, waiting to be judged glitches or the run's end
  std::string held_reason;
  bool dropped = false;  // rows were dropped since the last accepted one
  // Rows of the measured part waiting ReduceOptions::leave_guard_s before they are measured: dropped if the
  // machine is seen leaving its steady state before then.
  struct Waiting {
    Row u;  // on the run's clock, unwrapped
    bool gap = false, dropped = false;
    double t_record = 0.0;
    Deviations dev;
  };
  RingQueue<Waiting> guard;
  Deviations steady_dev;  // the largest of the measured rows
  // A static hold's encoder readings (deg, unwrapped, from the lines at the end of its settle time): its
  // angles stay within beta_tolerance_deg of them.
  double hold_theta = 0.0, hold_psi = 0.0;
  // The measured part.
  std::optional<DwellAccumulator> acc;
  bool measuring = false;  // the first row of the measured part has been measured
  double t_first = 0.0, theta_first = 0.0, psi_first = 0.0;
  std::vector<LineSums> phase_theta, phase_psi, phase_rel;  // rel: psi_r + theta
  // Successive differences of the main encoder's deviations inside stretches: the white part of its scatter
  // (quantisation, jitter), to tell a wandering rate from it.
  double diff_yy = 0, diff_yt = 0, diff_tt = 0, diff_n = 0, prev_y = 0, prev_tt = 0;
  std::vector<StretchSums> stretches;
  // The main axis' measured motion through the measured part (reduce/measured_rate.hpp): spinning dwells.
  std::optional<MeasuredMotionFit> motion;
  // The output's basis angle, piece by piece (Dwell::basis_angle), and the line and whole turns of the last.
  std::vector<BasisAngle> basis;
  std::size_t basis_serial = 0;
  double basis_turns = 0.0;
  double beta_sum = 0.0;
  std::size_t n = 0, gaps = 0;
  DwellQuality quality;
};

/// The rate at which the platform's heading sweeps the Earth rate through a spinning dwell at a counter rate
/// offset (docs/physics.md section 15); 0 without an offset, and at rate 0, where the heading turns with
/// gamma.
double heading_sweep_rad_s(double rate_rad_s, double offset_rad_s) {
  return rate_rad_s != 0.0 ? offset_rad_s : 0.0;
}

}  // namespace

PlanMatch match_to_plan(const TestSpec& plan, const ReduceOptions& options, double main_rate_rad_s,
                        double counter_rate_rad_s, double beta_deg, double gamma_deg) {
  PlanMatch m;
  const double tol0 = options.static_rate_tolerance_rad_s;
  m.is_static = std::abs(main_rate_rad_s) < tol0 && std::abs(counter_rate_rad_s) < tol0;
  // docs/physics.md section 15: the platform's heading (theta + psi_r) turns at the counter rate offset; a
  // plain test has the single offset 0.
  const double heading_rate = main_rate_rad_s + counter_rate_rad_s;
  bool has_offset = false;
  for (double o : plan.counter_rate_offsets_rad_s)
    if (o != 0.0) has_offset = true;
  const bool has_static =
      std::find(plan.rates_rad_s.begin(), plan.rates_rad_s.end(), 0.0) != plan.rates_rad_s.end() &&
      std::find(plan.counter_rate_offsets_rad_s.begin(), plan.counter_rate_offsets_rad_s.end(), 0.0) !=
          plan.counter_rate_offsets_rad_s.end();
  if (m.is_static) {
    if (!has_static) m.why_not = "the machine stands still and the plan has no static hold";
  } else if (std::abs(main_rate_rad_s) < tol0) {
    // At main rate 0 the counter platform turns at the offset alone: a plain rate table.
    double best = 0.0, best_rel = std::numeric_limits<double>::infinity();
    const bool has_zero_rate =
        std::find(plan.rates_rad_s.begin(), plan.rates_rad_s.end(), 0.0) != plan.rates_rad_s.end();
    if (has_zero_rate)
      for (double o : plan.counter_rate_offsets_rad_s) {
        if (o == 0.0) continue;
        const double rel = std::abs(heading_rate - o) / std::abs(o);
        if (rel < best_rel) best_rel = rel, best = o;
      }
    if (best_rel == std::numeric_limits<double>::infinity())
      m.why_not = fmt::format("the main axis stands still while the counter platform turns at {:.6g} rad/s",
                              counter_rate_rad_s);
    else if (best_rel > options.rate_tolerance)
      m.why_not = fmt::format(
          "the main axis stands still and the counter platform turns at {:.6g} rad/s, {:.2e} (relative) from "
          "the planned counter rate offset {} rad/s (rate_tolerance {:.0e})",
          counter_rate_rad_s, best_rel, best, options.rate_tolerance);
    m.planned_rate_rad_s = 0.0;
    m.planned_counter_rate_offset_rad_s = best;
  } else {
    double best = -1.0, best_rel = std::numeric_limits<double>::infinity();
    for (double r : plan.rates_rad_s) {
      if (r == 0.0) continue;
      const double rel = std::abs(main_rate_rad_s - r) / std::abs(r);
      if (rel < best_rel) best_rel = rel, best = r;
    }
    if (best < 0.0 && best_rel == std::numeric_limits<double>::infinity()) {
      m.why_not = "the main axis turns and the plan has no spinning rate";
    } else if (best_rel > options.rate_tolerance) {
      m.why_not = fmt::format(
          "the main axis turns at {:.6g} rad/s, {:.2e} (relative) from the planned {} rad/s "
          "(rate_tolerance {:.0e})",
          main_rate_rad_s, best_rel, best, options.rate_tolerance);
    } else {
      // The planned offset nearest the heading's rate, within rate_tolerance of the larger of |rate| and
      // |offset| (docs/rate_platform.md).
      double best_o = 0.0, best_d = std::numeric_limits<double>::infinity();
      for (double o : plan.counter_rate_offsets_rad_s) {
        const double d = std::abs(heading_rate - o) / std::max(std::abs(best), std::abs(o));
        if (d < best_d) best_d = d, best_o = o;
      }
      if (best_d > options.rate_tolerance) {
        if (!has_offset)
          m.why_not = fmt::format(
              "the counter platform turns at {:.6g} rad/s, not at minus the main rate {:.6g} rad/s",
              counter_rate_rad_s, main_rate_rad_s);
        else
          m.why_not = fmt::format(
              "the counter platform turns at {:.6g} rad/s, {:.6g} rad/s relative to minus the main rate "
              "{:.6g} rad/s, which matches no planned counter rate offset",
              counter_rate_rad_s, heading_rate, main_rate_rad_s);
      }
      m.planned_counter_rate_offset_rad_s = best_o;
    }
    m.planned_rate_rad_s = best;
  }
  if (!m.why_not.empty()) return m;
  const auto nearest = [](const std::vector<double>& planned_rad, double deg, double& best_deg) {
    double best = std::numeric_limits<double>::infinity();
    for (double p : planned_rad) {
      const double d = std::abs(wrap_deg_quick(deg - p * kRadToDeg));
      if (d < best) best = d, best_deg = p;
    }
    return best;
  };
  double b = 0.0;
  const double db = nearest(plan.beta_rad, beta_deg, b);
  if (db > options.beta_tolerance_deg) {
    m.why_not = fmt::format(
        "beta reads {:.3f} deg, {:.3f} deg from the nearest planned beta {:.3f} deg "
        "(beta_tolerance_deg {})",
        beta_deg, db, b * kRadToDeg, options.beta_tolerance_deg);
    return m;
  }
  m.beta_rad = b;
  if (m.is_static) {
    double g = 0.0;
    const double dg = nearest(plan.gamma_rad, gamma_deg, g);
    if (dg > options.beta_tolerance_deg) {
      m.why_not = fmt::format(
          "the static hold's gamma reads {:.3f} deg, {:.3f} deg from the nearest planned "
          "gamma {:.3f} deg (beta_tolerance_deg {})",
          gamma_deg, dg, g * kRadToDeg, options.beta_tolerance_deg);
      return m;
    }
    m.gamma_rad = g;
  }
  return m;
}

struct Reducer::State {
  TestSpec plan;
  ReduceOptions options;
  std::string source;
  double reference_rate = 0.0;
  double dt_planned = 0.0;
  std::size_t rows = 0;
  double t_last = 0.0;
  // Looking for a steady state: the last rows, unwrapped from one to the next (reset at a gap).
  std::deque<Row> window;
  double window_tested_at = -std::numeric_limits<double>::infinity();
  double raw_theta_prev = 0.0, raw_psi_prev = 0.0;
  std::optional<Run> run;
  // The dwells found, one a key (dwell_key): a repeat replaces the one kept only if it holds more samples
  // (the first of the longest is used), so that a record repeating its test keeps one test's dwells.
  std::vector<Dwell> dwells;
  std::vector<std::size_t> dwell_serial;  ///< per kept dwell: its number among all found, in time order
  std::map<DwellKey, std::size_t> dwell_of_key;
  std::size_t dwells_found = 0;
  std::vector<RejectedRun> rejected;
  WarningLog warnings;  ///< each dwell's
  WarningLog repeats;   ///< "the record repeats the dwell …"
  double worst_rate_offset = 0.0;
  int offset_dwells = 0;
  double last_run_start_s = -std::numeric_limits<double>::infinity();
  // take(): rows handed back while a row is being taken, and those waiting their turn.
  bool taking = false;
  std::vector<Row> handed_back;
  std::deque<Row> pending;
  // What the record holds, for the refusal of a record without a dwell for a planned position.
  RecordSummary summary;
  std::optional<RecordLayout> layout;
  // The measured samples go to the run's accumulator on a thread of its own (reduce/accumulator_feed.hpp).
  // Last: destroyed first, so that its worker has stopped before the run it feeds is destroyed.
  std::optional<AccumulatorFeed> feed{std::in_place};

  double hold_duration() const { return static_hold_duration_s(plan, reference_rate); }
  std::string at(double t) const { return fmt::format("{}: at t = {:.6f} s", source, t); }
  bool is_gap(double dt) const { return dt > options.gap_intervals * dt_planned; }

  // ---- Looking for a steady state -------------------------------------------------------------------
  /// Takes a row (raw encoder readings) while no run is in progress.
  void look(const Row& raw) {
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
    if (th.max_residual > options.angle_tolerance_deg || ps.max_residual > options.angle_tolerance_deg)
      return;
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
    const double th_tol = std::max(2.0 * th.max_residual, 1e-9),
                 ps_tol = std::max(2.0 * ps.max_residual, 1e-9);
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

  /// docs/rate_platform.md: in a plan with counter rate offsets, a window whose main axis is at a planned
  /// rate (or stopped) while the platform's heading (theta + psi_r) turns at no planned offset is an offset
  /// ramp or an index move, whose 20 deg/s^2 bends a window's line less than angle_tolerance_deg: no run
  /// starts there, so that the dwell after it is found from the ramp's end (a run started inside the ramp is
  /// matched on its last window, which still holds the ramp, and would be refused). A plain plan (the single
  /// offset 0) is not affected: there such a window starts a run, refused with its reason. The heading is
  /// held to rate_steadiness here, the tolerance the run's later windows must keep.
  bool offset_ramp(double main_rate_rad_s, double counter_rate_rad_s) const {
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
        if (std::abs(heading - o) <= options.rate_steadiness * std::max(std::abs(r), std::abs(o)))
          return false;
      }
      return true;
    }
    return false;
  }

  void take(const Row& raw) {
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

  void take_one(const Row& raw) {
    if (run)
      follow(raw);
    else
      look(raw);
  }

  void start_run(const Row& first, const Line& th, const Line& ps, double beta) {
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

  /// Matches the run to the plan, on the rates of its last window (check_rate), at time t (run's clock).
  void decide(Run& r, double t) {
    r.decided = true;
    r.hold_theta = r.theta_line(t);
    r.hold_psi = r.psi_line(t);
    r.match = match_to_plan(plan, options, r.rate_theta * kDegToRad, r.rate_psi * kDegToRad, r.beta_deg,
                            r.gamma_deg);
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
    r.acc.emplace(options, r.match.is_static ? std::vector<double>{r.match.gamma_rad} : spinning_gammas(plan),
                  r.match.is_static, 1, r.planned_duration, true, heading_sweep_rad_s(rate, offset));
  }

  // ---- Following a steady run -----------------------------------------------------------------------
  /// Takes a row into the run; ends the run (and hands the rows it held back to look()) when the machine
  /// has left its steady state.
  void follow(const Row& raw) {
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

  /// The rate, window by window, against the run's (and the lines the next rows are predicted from). False
  /// when the run ended here.
  bool check_rate(Run& r, const Row& u, double t, double t_record) {
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
        end_run(fmt::format("the rate changes by {:.2e} (relative; rate_steadiness {:.0e}) in the window "
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

  /// Takes a row of the measured part (on the run's clock) into the dwell; gap and dropped: the row follows
  /// a gap, or rows dropped as glitches.
  void measure(const Row& u, bool gap, bool dropped, double t_record) {
    Run& r = *run;
    // The plan says how long a dwell is: its measured part is [t_first, t_first + planned duration) on the
    // dwell's clock.
    if (r.measuring && u.t >= r.t_first + r.planned_duration - 1e-9) {
      ++r.quality.beyond_planned_rows;
      return;
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
                         kMeasuredKnotRevolutions * 2.0 * kPi / std::max(gamma_rate, 1e-9),
                         r.planned_duration);
        r.motion->begin_phase(u.t);
      }
    } else if (gap || dropped) {
      if (r.stretches.size() >= static_cast<std::size_t>(options.max_stretches_per_dwell)) {
        end_run(fmt::format(
                    "gaps and dropped rows break it into more than {} stretches (max_stretches_per_dwell) "
                    "by t = {:.3f} s",
                    options.max_stretches_per_dwell, t_record),
                Ending::kStretches);
        return;
      }
      if (gap) {
        ++r.gaps;
        feed->break_revolution(*r.acc);
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
    if (r.motion)
      r.motion->add(st.first + static_cast<double>(st.count - 1) * dt_planned, u.theta * kDegToRad);
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
      // Recorded for the channels (Dwell::basis_angle): a piece where the line or its whole turns change.
      // psi - line is a whole number of turns up to rounding: the nearest by a truncating conversion (a
      // call of libm's round a row was 1 % of calibrate's time).
      const double q = r.psi_line_valid ? (psi - r.psi_line(u.t)) * (1.0 / 360.0) : 0.0;
      const double turns =
          360.0 * static_cast<double>(static_cast<std::int64_t>(q + (q >= 0.0 ? 0.5 : -0.5)));
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
    feed->add(*r.acc, u.t, -psi * kDegToRad, u.y);
  }

  void reject(const Run& r, std::string reason) {
    RejectedRun x;
    x.start_s = r.start_s;
    x.end_s = r.end_s;
    x.main_rate_rad_s = r.rate_theta * kDegToRad;
    x.counter_rate_rad_s = r.rate_psi * kDegToRad;
    x.beta_deg = r.beta_deg;
    x.gamma_deg = r.gamma_deg;
    x.is_static = std::abs(r.rate_theta) * kDegToRad < options.static_rate_tolerance_rad_s &&
                  std::abs(r.rate_psi) * kDegToRad < options.static_rate_tolerance_rad_s;
    x.reason = std::move(reason);
    rejected.push_back(std::move(x));
    if (rejected.size() > kRejectedKept) {
      const auto shortest = std::min_element(
          rejected.begin(), rejected.end(),
          [](const auto& a, const auto& b) { return a.end_s - a.start_s < b.end_s - b.start_s; });
      rejected.erase(shortest);
    }
  }

  /// How a run ends: the machine left its steady state (the rows waiting in the guard are dropped), the
  /// record ended (they are measured), or its gaps broke it into too many stretches (the rest is not used).
  enum class Ending { kLeft, kRecordEnds, kStretches };

  /// Ends the run in progress: a dwell if it matched the plan and is long enough, otherwise a rejected run
  /// with its reason. The rows it held go back to look().
  void end_run(std::string reason, Ending how) {
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

  void finish_run(Run& r) {
    if (!r.decided) {
      if (r.end_s - r.start_s < plan.settle_s)
        reject(r, fmt::format("it lasted {:.3f} s, less than its settle time of {} s: {}",
                              r.end_s - r.start_s, plan.settle_s, r.quality.ended));
      else
        reject(r, fmt::format("its rate did not hold within rate_steadiness ({:.0e}) from one {} s window to "
                              "the next after its settle time of {} s: {}",
                              options.rate_steadiness, options.window_s, plan.settle_s, r.quality.ended));
      return;
    }
    if (!r.matched) {
      reject(r, fmt::format("{} (the run ended: {})", r.match.why_not, r.quality.ended));
      return;
    }
    const bool long_enough =
        r.n >= 2 && (r.match.is_static ? r.n >= static_cast<std::size_t>(2 * options.static_batches)
                                       : r.acc->complete_revolutions() >= 1);
    if (!long_enough) {
      reject(r, fmt::format("it measured only {:.3f} s of the {:.3f} s planned: {}",
                            r.measuring ? r.acc->last_time_s() - r.t_first : 0.0, r.planned_duration,
                            r.quality.ended));
      return;
    }
    Dwell d;
    d.is_static = r.match.is_static;
    d.planned_rate_rad_s = r.match.planned_rate_rad_s;
    d.planned_counter_rate_offset_rad_s = r.match.planned_counter_rate_offset_rad_s;
    d.measured_beta_rad = r.beta_sum / static_cast<double>(r.n) * kDegToRad;
    // The channels take the plan's beta (and a static hold's gamma): an encoder's mean reading at rest is
    // biased by up to half a count (docs/calibration.md).
    d.beta_rad = r.match.beta_rad;
    d.gammas_rad = d.is_static ? std::vector<double>{r.match.gamma_rad} : spinning_gammas(plan);
    d.first_time_s = r.acc->first_time_s();
    d.last_time_s = r.acc->last_time_s();
    d.samples = r.n;
    d.gaps = r.gaps;
    d.planned_duration_s = r.planned_duration;
    d.quality = r.quality;
    // The encoders' lines: one rate over the dwell, an intercept per phase (a gap starts one).
    double sty_t = 0, stt_t = 0, sty_p = 0, stt_p = 0, res_t = 0, res_p = 0;
    for (std::size_t k = 0; k < r.phase_theta.size(); ++k) {
      sty_t += r.phase_theta[k].sty();
      stt_t += r.phase_theta[k].stt();
      sty_p += r.phase_psi[k].sty();
      stt_p += r.phase_psi[k].stt();
    }
    // The counter platform's rate relative to the arm's (psi_r + theta, a heading drift about Up) enters
    // omega_I whole. Fitted over a few seconds of encoders quantised to 0.1 deg it carries ~1e-5 rad/s
    // (2 deg/h) of quantisation error, so it is used only where it is resolved: beyond 3 of its standard
    // errors (a noise-free record always); otherwise the platform turns at exactly minus the main rate
    // (docs/calibration.md).
    (void)sty_p;
    (void)stt_p;
    double sty_r = 0, stt_r = 0, syy_r = 0, n_r = 0;
    for (const LineSums& x : r.phase_rel) sty_r += x.sty(), stt_r += x.stt(), syy_r += x.syy(), n_r += x.n;
    const double br = stt_r > 0 ? sty_r / stt_r : 0.0;
    const double dof_r = n_r - 1.0 - static_cast<double>(r.phase_rel.size());
    const double se_r =
        dof_r > 0 && stt_r > 0 ? std::sqrt(std::max(syy_r - br * sty_r, 0.0) / dof_r / stt_r) : 0.0;
    const double bt = stt_t > 0 ? sty_t / stt_t : 0.0, bp = -bt + (std::abs(br) > 3.0 * se_r ? br : 0.0);
    for (std::size_t k = 0; k < r.phase_theta.size(); ++k) {
      res_t += std::max(r.phase_theta[k].syy() - bt * r.phase_theta[k].sty(), 0.0);
      res_p += std::max(r.phase_psi[k].syy() - bp * r.phase_psi[k].sty(), 0.0);
    }
    const double planned_deg_s = r.match.planned_rate_rad_s * kRadToDeg;
    // The counter platform turns at -rate + offset relative to the arm (docs/physics.md section 15).
    const double planned_counter_deg_s =
        -planned_deg_s + r.match.planned_counter_rate_offset_rad_s * kRadToDeg;
    const auto intercept = [&](const LineSums& s, double b) { return (s.y - b * s.t) / s.n; };
    const double nd = static_cast<double>(r.n);
    d.main = {(r.theta_first + intercept(r.phase_theta[0], bt)) * kDegToRad, (planned_deg_s + bt) * kDegToRad,
              std::sqrt(res_t / nd) * kDegToRad};
    d.counter = {(r.psi_first + intercept(r.phase_psi[0], bp)) * kDegToRad,
                 (planned_counter_deg_s + bp) * kDegToRad, std::sqrt(res_p / nd) * kDegToRad};
    double span = 0.0;
    std::size_t steps = 0;
    for (const StretchSums& st : r.stretches) {
      TimeStretch ts;
      ts.first_time_s = st.first;
      ts.count = st.count;
      ts.interval_s = st.count > 1 ? (st.last - st.first) / static_cast<double>(st.count - 1) : dt_planned;
      const double tt = st.first - r.t_first;
      ts.main_at_first_rad =
          (r.theta_first + intercept(r.phase_theta[st.phase], bt) + (planned_deg_s + bt) * tt) * kDegToRad;
      ts.counter_at_first_rad =
          (r.psi_first + intercept(r.phase_psi[st.phase], bp) + (planned_counter_deg_s + bp) * tt) *
          kDegToRad;
      d.stretches.push_back(ts);
      span += st.last - st.first;
      steps += st.count - 1;
    }
    d.sample_interval_s = steps > 0 ? span / static_cast<double>(steps) : dt_planned;
    if (r.motion) {
      d.measured = r.motion->finish();
      for (const StretchSums& st : r.stretches) d.measured.stretch_phase.push_back(st.phase);
      d.basis_angle = std::move(r.basis);
      d.basis_angle.shrink_to_fit();  // held to the end: its size, not the capacity its growth left
    }
    const double beta_deg = d.beta_rad * kRadToDeg;
    const std::string what =
        d.is_static ? fmt::format("static hold at beta {:.4f} deg, gamma {:.4f} deg", beta_deg,
                                  d.gammas_rad[0] * kRadToDeg)
        : d.planned_counter_rate_offset_rad_s != 0.0
            ? fmt::format("dwell at {} rad/s, counter rate offset {} rad/s, beta {:.4f} deg",
                          d.planned_rate_rad_s, d.planned_counter_rate_offset_rad_s, beta_deg)
            : fmt::format("dwell at {} rad/s, beta {:.4f} deg", d.planned_rate_rad_s, beta_deg);
    d.gyro = r.acc->finish(0);
    // docs/physics.md section 14: a dwell that loses many samples is warned about (1 % is far above the rate
    // at which clean noise reaches the rule's threshold).
    const std::string place = fmt::format("the {} at t = {:.3f} s", what, d.first_time_s);
    if (static_cast<double>(d.gyro.outliers) > 0.01 * static_cast<double>(d.samples))
      warnings.add("outliers",
                   fmt::format("{}: {}: {} of its {} samples ({:.1f} %) were rejected as outliers (beyond {} "
                               "robust standard deviations of the dwell's fit) and left out of it.",
                               at(d.first_time_s), what, d.gyro.outliers, d.samples,
                               100.0 * static_cast<double>(d.gyro.outliers) / static_cast<double>(d.samples),
                               options.outlier_threshold),
                   place);
    // Checks a test engineer wants to hear about.
    const double measured = d.last_time_s - d.first_time_s + d.sample_interval_s;
    if (measured < d.planned_duration_s - 2.0 * d.sample_interval_s) {
      warnings.add("short",
                   fmt::format("{}: {} lasted {:.3f} s of the {:.3f} s planned ({} revolutions): {}.",
                               at(d.first_time_s), what, measured, d.planned_duration_s, plan.revolutions,
                               r.quality.ended),
                   place);
    }
    // A rate that wanders: the main encoder's scatter about its line beyond its white part (half the mean
    // square of successive differences: quantisation and stamp jitter), which the channels' constant-rate
    // line does not follow.
    const double white2 =
        r.diff_n > 0 ? 0.5 * (r.diff_yy - 2.0 * bt * r.diff_yt + bt * bt * r.diff_tt) / r.diff_n : 0.0;
    const double wander_deg = std::sqrt(std::max(res_t / nd - white2, 0.0));
    if (wander_deg > options.wander_warning_deg) {
      warnings.add("wander",
                   fmt::format("{}: the rate wanders during the {}: the main encoder leaves a constant-rate "
                               "line by {:.4f} deg RMS beyond its sample-to-sample scatter.",
                               at(d.first_time_s), what, wander_deg),
                   place);
    }
    if (!d.is_static && d.planned_rate_rad_s != 0.0) {
      const double rel = std::abs(d.main.rate_rad_s - d.planned_rate_rad_s) / std::abs(d.planned_rate_rad_s);
      if (rel > 1e-4) {
        ++offset_dwells;
        worst_rate_offset = std::max(worst_rate_offset, rel);
      }
    }
    keep(std::move(d));
  }

  /// Keeps a found dwell: the first of its key, or a repeat holding more samples than the one kept.
  void keep(Dwell d) {
    const std::size_t serial = dwells_found++;
    const auto [it, first] = dwell_of_key.emplace(dwell_key(d), dwells.size());
    if (first) {
      dwells.push_back(std::move(d));
      dwell_serial.push_back(serial);
      return;
    }
    repeats.add("repeat",
                fmt::format("{}: the record repeats the dwell at {} rad/s, beta {:.4f} deg; the "
                            "longer one is used.",
                            source, d.planned_rate_rad_s, d.beta_rad * kRadToDeg),
                fmt::format("the dwell at {} rad/s, beta {:.4f} deg at t = {:.3f} s", d.planned_rate_rad_s,
                            d.beta_rad * kRadToDeg, d.first_time_s));
    if (d.samples > dwells[it->second].samples) {
      dwells[it->second] = std::move(d);
      dwell_serial[it->second] = serial;
    }
  }

  /// The most telling rejected run for a planned position that has no dwell.
  std::string why_missing(const Position& p) const {
    const RejectedRun* best = nullptr;
    int best_rank = 0;
    for (const RejectedRun& x : rejected) {
      const bool is_static = p.rate_rad_s == 0.0 && p.counter_rate_offset_rad_s == 0.0;
      if (x.is_static != is_static) continue;
      const double db = std::abs(wrap_deg_quick(x.beta_deg - p.beta_rad * kRadToDeg));
      // A rate table at main rate 0 (docs/physics.md section 15): the main axis' rate against the stopped
      // tolerance.
      const double dr = is_static ? 0.0
                        : p.rate_rad_s == 0.0
                            ? (std::abs(x.main_rate_rad_s) < options.static_rate_tolerance_rad_s ? 0.0 : 1.0)
                            : std::abs(x.main_rate_rad_s - p.rate_rad_s) / std::abs(p.rate_rad_s);
      const double dg = is_static ? std::abs(wrap_deg_quick(x.gamma_deg - p.gamma_rad * kRadToDeg)) : 0.0;
      if (db > 5.0 || dr > 0.05 || dg > 5.0) continue;
      const int rank = (db <= options.beta_tolerance_deg ? 2 : 0) + (dr <= options.rate_tolerance ? 1 : 0);
      if (!best || rank > best_rank ||
          (rank == best_rank && x.end_s - x.start_s > best->end_s - best->start_s)) {
        best = &x;
        best_rank = rank;
      }
    }
    if (!best) return "no steady run of the record comes near it";
    return fmt::format("the steady run at t = {:.3f} s to {:.3f} s gave no dwell: {}", best->start_s,
                       best->end_s, best->reason);
  }
};

Reducer::Reducer(const PlannedTest& plan, const ReduceOptions& options, std::string source_name)
    : state_(std::make_unique<State>()) {
  std::string error;
  if (!options.IsValid(&error)) throw Error("reduction options: " + error + ".");
  state_->plan = plan.spec;
  state_->options = options;
  state_->source = std::move(source_name);
  state_->dt_planned = 1.0 / plan.spec.sample_rate_hz;
  state_->reference_rate = reference_rate_rad_s(plan.spec, plan.reference_rate_rad_s);
  if (state_->reference_rate == 0.0 && !(plan.spec.static_hold_s > 0.0))
    throw Error(
        "the plan has no non-zero rate, no [test] static_hold_s and no reference rate to size the static "
        "holds.");
  check_test_feasible(plan.spec, options, state_->reference_rate);
  check_calibration_memory(plan.spec, options);
}

Reducer::~Reducer() = default;

void Reducer::set_threaded_accumulation(bool threaded) {
  if (state_->rows > 0) throw Error("Reducer::set_threaded_accumulation: only before the first row.");
  state_->feed.emplace(threaded);
}

void Reducer::set_record_layout(const std::optional<RecordLayout>& layout) {
  state_->layout = layout;
}

void Reducer::push(const RecordSample& s) {
  push_unsummarised(s);
  state_->summary.add(s);
}

void Reducer::push_unsummarised(const RecordSample& s) {
  State& st = *state_;
  if (st.rows > 0 && !(s.time_s > st.t_last))
    throw Error(fmt::format("{}: time does not increase.", st.at(s.time_s)));
  ++st.rows;
  st.t_last = s.time_s;
  st.take(Row{s.time_s, s.main_angle_deg, s.counter_angle_deg, s.position_angle_deg, s.output});
}

std::size_t Reducer::dwells_held() const {
  return state_->dwells.size();
}

void Reducer::set_summary(const RecordSummary& summary) {
  state_->summary = summary;
}

Reduction Reducer::finish() {
  State& st = *state_;
  while (st.run) st.end_run("the record ends", State::Ending::kRecordEnds);
  Reduction out;
  out.samples_read = st.rows;
  out.warnings = st.warnings.lines();
  if (st.offset_dwells > 0)
    out.warnings.push_back(
        fmt::format("{}: in {} dwell{} the main axis turned up to {:.2e} (relative) off the planned rate; "
                    "the measured rates "
                    "are used.",
                    st.source, st.offset_dwells, st.offset_dwells > 1 ? "s" : "", st.worst_rate_offset));
  // One dwell per (rate, beta) or (0, beta, gamma): the longest if the record has several (kept as they were
  // found, State::keep), in time order.
  for (std::string& w : st.repeats.lines()) out.warnings.push_back(std::move(w));
  std::vector<std::size_t> in_time_order(st.dwells.size());
  for (std::size_t i = 0; i < in_time_order.size(); ++i) in_time_order[i] = i;
  std::sort(in_time_order.begin(), in_time_order.end(),
            [&](std::size_t a, std::size_t b) { return st.dwell_serial[a] < st.dwell_serial[b]; });
  std::map<DwellKey, int> chosen;  // the dwell of each key, numbered as in out.dwells
  for (std::size_t i : in_time_order) {
    // Moved, not copied: a dwell holds a few numbers a revolution (docs/performance.md).
    chosen[dwell_key(st.dwells[i])] = static_cast<int>(out.dwells.size());
    out.dwells.push_back(std::move(st.dwells[i]));
    out.samples_used += out.dwells.back().samples;
    out.outliers += out.dwells.back().gyro.outliers;
    out.gaps += out.dwells.back().gaps;
    out.encoder_glitch_rows += out.dwells.back().quality.encoder_glitch_rows;
  }
  st.dwells.clear();
  st.dwell_of_key.clear();
  out.rejected = st.rejected;
  std::sort(out.rejected.begin(), out.rejected.end(),
            [](const RejectedRun& a, const RejectedRun& b) { return a.start_s < b.start_s; });
  std::vector<std::string> missing;
  for (const Position& p : test_positions(st.plan)) {
    const bool is_static = p.rate_rad_s == 0.0 && p.counter_rate_offset_rad_s == 0.0;
    const auto key =
        std::make_tuple(p.rate_rad_s, p.counter_rate_offset_rad_s, p.beta_rad, is_static ? p.gamma_rad : 0.0);
    const auto it = chosen.find(key);
    if (it == chosen.end()) {
      missing.push_back(
          fmt::format("position {} (rate {} rad/s, {}beta {} deg, gamma {} deg): {}", p.index, p.rate_rad_s,
                      p.counter_rate_offset_rad_s != 0.0
                          ? fmt::format("counter rate offset {} rad/s, ", p.counter_rate_offset_rad_s)
                          : std::string(),
                      p.beta_rad * kRadToDeg, p.gamma_rad * kRadToDeg, st.why_missing(p)));
      continue;
    }
    const int di = it->second;
    out.positions.push_back(reduced_position(p, out.dwells[static_cast<std::size_t>(di)], di));
  }
  if (!missing.empty()) {
    std::string list;
    for (std::size_t i = 0; i < missing.size() && i < 4; ++i) list += (i ? "; " : "") + missing[i];
    if (missing.size() > 4) list += fmt::format("; and {} more", missing.size() - 4);
    throw Error(fmt::format("{}: the record has no usable dwell for {} planned position{}: {}. {}", st.source,
                            missing.size(), missing.size() > 1 ? "s" : "", list,
                            st.summary.describe(st.plan, st.layout, st.rejected, st.dwells_found)));
  }
  // A standard error is the scatter between revolutions (or batches) about a line: without a degree of
  // freedom left there is no measurement of the noise, and no number may stand in for one
  // (docs/calibration.md, "Degrees of freedom").
  int zero = 0;
  for (const Dwell& d : out.dwells) {
    if (d.gyro.dof > 0.0) continue;
    // The scatter is about a mean (and a drift), and at a counter rate offset also the heading's sweep.
    const int needed =
        d.is_static
            ? 2
            : (st.options.linear_drift ? 3 : 2) +
                  (heading_sweep_rad_s(d.planned_rate_rad_s, d.planned_counter_rate_offset_rad_s) != 0.0 ? 2
                                                                                                         : 0);
    if (d.gyro.revolutions >= needed) {
      // Enough revolutions, but their scatter overflowed: outputs whose squares leave a double's range (a
      // record's reader refuses them, limits::kOutputMagnitude; a caller pushing samples may not have).
      double largest = 0.0;
      for (double v : d.gyro.value)
        if (!(std::abs(v) <= largest)) largest = std::abs(v);
      throw Error(fmt::format(
          "{}: at t = {:.6f} s the {} at {} rad/s, beta {:.4f} deg has {} complete {}, but the scatter "
          "between "
          "them is not a finite number: its outputs reach {:g}, whose squares leave a double's range (an "
          "output is at most {:g} in magnitude, limits::kOutputMagnitude).",
          st.source, d.first_time_s, d.is_static ? "static hold" : "dwell", d.planned_rate_rad_s,
          d.beta_rad * kRadToDeg, d.gyro.revolutions, d.is_static ? "batches" : "revolutions", largest,
          limits::kOutputMagnitude));
    }
    throw Error(fmt::format(
        "{}: at t = {:.6f} s the {} at {} rad/s, beta {:.4f} deg has {} complete {}, too few for a standard "
        "error from the scatter between them; it needs at least {}{}.",
        st.source, d.first_time_s, d.is_static ? "static hold" : "dwell", d.planned_rate_rad_s,
        d.beta_rad * kRadToDeg, d.gyro.revolutions, d.is_static ? "batches" : "revolutions", needed,
        d.is_static ? ""
        : st.options.method == ReduceOptions::Method::kWindowMean
            ? ": raise [test] revolutions (window means count a revolution only when it passes through every "
              "window, so a dwell's first or last may not count)"
            : fmt::format(" ([test] revolutions = {} or more)", needed)));
  }
  for (const ReducedPosition& p : out.positions)
    if (p.std_err_deg_h == 0.0) ++zero;
  if (zero > 0)
    out.warnings.push_back(
        fmt::format("{}: {} position{} show no scatter at all between revolutions: a "
                    "noise-free record, whose uncertainties mean nothing.",
                    st.source, zero, zero > 1 ? "s" : ""));
  return out;
}

ReducedPosition reduced_position(const Position& p, const Dwell& d, int dwell_index) {
  int slot = 0;
  for (std::size_t k = 0; k < d.gammas_rad.size(); ++k)
    if (d.gammas_rad[k] == p.gamma_rad) slot = static_cast<int>(k);
  const auto k = static_cast<std::size_t>(slot);
  ReducedPosition rp;
  rp.index = p.index;
  rp.rate_rad_s = p.rate_rad_s;
  rp.beta_rad = p.beta_rad;
  rp.gamma_rad = p.gamma_rad;
  rp.counter_rate_offset_rad_s = p.counter_rate_offset_rad_s;
  rp.mean_deg_h = d.gyro.value[k];
  rp.std_err_deg_h = d.gyro.std_err[k];
  rp.samples = d.gyro.samples[k];
  rp.outliers = d.gyro.outliers;
  rp.dwell = dwell_index;
  rp.gamma_slot = slot;
  return rp;
}

namespace {

/// Rows read ahead by the reader's thread: kReadAheadBatches batches of kReadAheadRows rows (3.4 MB).
constexpr std::size_t kReadAheadRows = 8192;
constexpr std::size_t kReadAheadBatches = 4;

/// The reader on a thread of its own, a few batches of rows ahead of the caller's thread (docs/
/// performance.md): parsing and reducing overlap. Rows arrive in the record's order; an error of the reader
/// (gyrocal::Error naming the file and line) is rethrown by next() where its row would have been. The
/// thread parses only: with the accumulation on a third thread, parsing is the longest of the three, so the
/// record's summary and the caller's observer run on the caller's thread (docs/performance.md).
class ReadAhead {
 public:
  explicit ReadAhead(RecordReader& reader) : reader_(reader), batches_(kReadAheadBatches) {
    for (auto& b : batches_) b.rows.resize(kReadAheadRows);
    thread_ = std::thread([this] { produce(); });
  }
  ~ReadAhead() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  ReadAhead(const ReadAhead&) = delete;
  ReadAhead& operator=(const ReadAhead&) = delete;

  /// The next batch of rows (empty at the end of the record); valid until the next call.
  std::span<const RecordSample> next() {
    std::unique_lock<std::mutex> lock(mutex_);
    if (holding_) {  // the caller is done with the batch it held: its slot is free again
      holding_ = false;
      // The rows read before an error went first; the error comes where the next row would have been.
      if (batches_[head_].error) std::rethrow_exception(batches_[head_].error);
      head_ = (head_ + 1) % batches_.size();
      --filled_;
      changed_.notify_all();
    }
    changed_.wait(lock, [&] { return filled_ > 0; });
    Batch& b = batches_[head_];
    if (b.error && b.count == 0) std::rethrow_exception(b.error);
    holding_ = true;
    return {b.rows.data(), b.count};
  }

 private:
  struct Batch {
    std::vector<RecordSample> rows;
    std::size_t count = 0;
    std::exception_ptr error;
  };
  void produce() {
    std::size_t tail = 0;
    bool ended = false;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return stop_ || filled_ < batches_.size(); });
        if (stop_) return;
      }
      Batch& b = batches_[tail];
      b.count = 0;
      try {
        while (!ended && b.count < b.rows.size()) {
          if (reader_.next(b.rows[b.count]))
            ++b.count;
          else
            ended = true;
        }
      } catch (...) {
        b.error = std::current_exception();
      }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++filled_;
      }
      changed_.notify_all();
      // The end of the record is an empty batch (or an error): the consumer stops there.
      if (b.count == 0 || b.error) return;
      tail = (tail + 1) % batches_.size();
    }
  }

  RecordReader& reader_;
  std::vector<Batch> batches_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::size_t head_ = 0, filled_ = 0;
  bool holding_ = false, stop_ = false;
};

}  // namespace

Reduction reduce_record(RecordReader& reader, const TestSpec& plan, const ReduceOptions& options,
                        double reference_rate_rad_s,
                        const std::function<void(std::span<const RecordSample>)>& observe) {
  Reducer reducer(PlannedTest{plan, reference_rate_rad_s}, options, reader.name());
  reducer.set_record_layout(reader.layout());
  RecordSummary summary;  // of every row read
  ReadAhead ahead(reader);
  for (auto rows = ahead.next(); !rows.empty(); rows = ahead.next()) {
    for (const RecordSample& s : rows) summary.add(s);
    if (observe) observe(rows);
    for (const RecordSample& s : rows) reducer.push_unsummarised(s);
  }
  reducer.set_summary(summary);
  return reducer.finish();
}

}  // namespace gyrocal
