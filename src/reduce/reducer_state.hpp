#pragma once
// The reducer's state (reduce/reducer.hpp): the row, line and run types it works with, and Reducer::State,
// whose work is cut by job: steady_runs.cpp finds a steady state and follows a run row by row (the per-row
// path, kept in one file so that it is compiled as one), dwell_building.cpp ends a run into a dwell or a
// rejected run, reducer.cpp finishes the reduction. Internal to src/reduce.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/core/limits.hpp"
#include "gyrocal/reduce/accumulator_feed.hpp"
#include "gyrocal/reduce/record_summary.hpp"
#include "gyrocal/reduce/reducer.hpp"

namespace gyrocal {
namespace reduce_detail {

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
  double y = 0.0;                             // the first output column's value (a lone sensor's output)
  // The row's number in the record: the values of its other output columns, with several, are kept once
  // in Reducer::State::more_outputs (a row is copied a few times on its way; it stays this small).
  std::uint64_t serial = 0;
};

/// The encoder of a row's first reading (main, counter, position) that no encoder writes: beyond
/// limits::kEncoderAngleDeg in magnitude, or not a number; nullptr when all three are readings. Such a value
/// cannot be wrapped onto a turn (1e308 lies nowhere on it): it is a glitch, never a reading on the line.
inline const char* unreadable_encoder(const Row& r) {
  constexpr double kMax = limits::kEncoderAngleDeg;
  if (std::abs(r.theta) <= kMax && std::abs(r.psi) <= kMax && std::abs(r.beta) <= kMax) [[likely]]
    return nullptr;
  return !(std::abs(r.theta) <= kMax) ? "main" : !(std::abs(r.psi) <= kMax) ? "counter" : "position";
}

/// The reading of `encoder` ("main", "counter" or "position") in r.
inline double encoder_reading(const Row& r, std::string_view encoder) {
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
inline double median_of(std::vector<double> v) {
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
inline DwellKey dwell_key(const Dwell& d) {
  return {d.planned_rate_rad_s, d.planned_counter_rate_offset_rad_s, d.beta_rad,
          d.is_static ? d.gammas_rad[0] : 0.0};
}

/// Steady runs that gave no dwell are kept, the longest first, up to this many (bounded memory).
inline constexpr std::size_t kRejectedKept = 256;
/// The window of rows searched for a steady state never holds more than this many rows.
inline constexpr std::size_t kMaxWindowRows = std::size_t{1} << 16;
/// The rows waiting ReduceOptions::leave_guard_s before they are measured never exceed this many (15 MB; at
/// 1 MHz the guard is then 0.26 s).
inline constexpr std::size_t kMaxGuardRows = std::size_t{1} << 18;

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
  // One accumulator per output column, fed the same samples (Reducer::set_output_columns); the first's
  // sample count, times and revolutions are the dwell's.
  std::vector<DwellAccumulator> accs;
  bool measuring = false;  // the first row of the measured part has been measured
  // A record with increments: the row after a gap was left out (its interval unknown), so the next row
  // measured takes the gap's place (a new stretch and phase).
  bool gap_pending = false;
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
inline double heading_sweep_rad_s(double rate_rad_s, double offset_rad_s) {
  return rate_rad_s != 0.0 ? offset_rad_s : 0.0;
}

}  // namespace reduce_detail

using namespace reduce_detail;  // the reducer's own types, in the files that include this internal header

// The members of the per-row path are declared inline and defined in steady_runs.cpp, the one file that calls
// them (Reducer::push_unsummarised is its entry): GCC then inlines them into one another as it did when they
// were defined in the class, which the reducer's time per row depends on.
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
  std::vector<Dwell> dwells;  // Dwell::output: the first output column's values
  /// Per kept dwell: the reduced values of the output columns after the first (empty with one column).
  std::vector<std::vector<DwellValues>> more_outputs;
  /// The output columns each row holds (RecordSample::outputs) and, with more than one, their names for
  /// messages.
  std::size_t outputs = 1;
  std::vector<std::string> output_names;
  /// The record holds an increment column (Reducer::set_increments).
  bool increments = false;
  /// With several output columns: the values of the columns after the first of every row still held
  /// (window, a run's held rows and guard), by serial from more_front on. Memory: the rows held, no more.
  std::deque<std::array<double, limits::kMaxOutputColumns - 1>> more_outputs_of_rows;
  std::uint64_t more_front = 0;

  /// Keeps the row's other output columns (several columns only), first dropping those of rows no longer
  /// held.
  void keep_more_outputs(const RecordSample& s);
  /// The values of every output column of row `u` into `values` (several columns only). Throws if the row's
  /// other columns are no longer kept (an internal error: never a silent wrong value).
  void row_outputs(const Row& u, double* values) const;
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
  inline void look(const Row& raw);

  /// docs/rate_platform.md: in a plan with counter rate offsets, a window whose main axis is at a planned
  /// rate (or stopped) while the platform's heading (theta + psi_r) turns at no planned offset is an offset
  /// ramp or an index move, whose 20 deg/s^2 bends a window's line less than angle_tolerance_deg: no run
  /// starts there, so that the dwell after it is found from the ramp's end (a run started inside the ramp is
  /// matched on its last window, which still holds the ramp, and would be refused). A plain plan (the single
  /// offset 0) is not affected: there such a window starts a run, refused with its reason. The heading is
  /// held to rate_steadiness here, the tolerance the run's later windows must keep.
  inline bool offset_ramp(double main_rate_rad_s, double counter_rate_rad_s) const;

  inline void take(const Row& raw);

  inline void take_one(const Row& raw);

  inline void start_run(const Row& first, const Line& th, const Line& ps, double beta);

  /// Matches the run to the plan, on the rates of its last window (check_rate), at time t (run's clock).
  inline void decide(Run& r, double t);

  // ---- Following a steady run -----------------------------------------------------------------------
  /// Takes a row into the run; ends the run (and hands the rows it held back to look()) when the machine
  /// has left its steady state.
  inline void follow(const Row& raw);

  /// The rate, window by window, against the run's (and the lines the next rows are predicted from). False
  /// when the run ended here.
  inline bool check_rate(Run& r, const Row& u, double t, double t_record);

  /// Takes a row of the measured part (on the run's clock) into the dwell; gap and dropped: the row follows
  /// a gap, or rows dropped as glitches.
  inline void measure(const Row& u, bool gap, bool dropped, double t_record);

  void reject(const Run& r, std::string reason);

  /// How a run ends: the machine left its steady state (the rows waiting in the guard are dropped), the
  /// record ended (they are measured), or its gaps broke it into too many stretches (the rest is not used).
  enum class Ending { kLeft, kRecordEnds, kStretches };

  /// Ends the run in progress: a dwell if it matched the plan and is long enough, otherwise a rejected run
  /// with its reason. The rows it held go back to look().
  void end_run(std::string reason, Ending how);

  void finish_run(Run& r);

  /// Keeps a found dwell: the first of its key, or a repeat holding more samples than the one kept.
  void keep(Dwell d, std::vector<DwellValues> more);

  /// The one-column Reduction of every kept dwell (their first column's values), with the record's checks:
  /// Reducer::finish's work, before it splits the output columns (finish_channels).
  Reduction finish_first_column();
  /// Per kept dwell in finish_first_column's order: its other columns' values (more_outputs), until
  /// finish_channels takes them.
  std::vector<std::vector<DwellValues>> chosen_more;
  /// Refuses a reduction (`column` names its output column in messages, or "" for a lone one) in which a
  /// dwell has no degree of freedom for its standard errors; warns of positions without scatter.
  void check_degrees_of_freedom(Reduction& r, const std::string& column) const;

  /// The most telling rejected run for a planned position that has no dwell.
  std::string why_missing(const Position& p) const;
};

}  // namespace gyrocal
