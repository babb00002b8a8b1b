#pragma once
// Reduce a record, read as a stream: split it into dwells from the encoder angles, drop the settle
// interval, and reduce each dwell to one value per gamma of the plan (reduce/dwell_accumulator.hpp).
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "gyrocal/plan/positions.hpp"
#include "gyrocal/plan/test_spec.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/reduce/dwell_accumulator.hpp"
#include "gyrocal/reduce/measured_rate.hpp"
#include "gyrocal/reduce/record_summary.hpp"

namespace gyrocal {

/// A straight line angle(t) = at_first + rate * (t - t_first), fitted to unwrapped encoder readings.
struct AngleLine {
  double at_first_rad = 0.0;
  double rate_rad_s = 0.0;
  double rms_residual_rad = 0.0;  ///< scatter of the readings about the line
  double at(double t, double t_first) const { return at_first_rad + rate_rad_s * (t - t_first); }
};

/// A stretch of a dwell's measured part sampled without a break: `count` samples evenly spaced from
/// first_time_s, on the dwell's clock (docs/calibration.md: inside a dwell each gap counts as one sample
/// interval), with the encoders' lines at its first sample. A gap or a dropped row (an encoder glitch) starts
/// a new stretch; after a gap the encoders' phase is measured afresh (a clock jump keeps no phase).
struct TimeStretch {
  double first_time_s = 0.0;
  double interval_s = 0.0;  ///< mean interval between its samples (the planned one for a single sample)
  std::size_t count = 0;
  double main_at_first_rad = 0.0;     ///< theta on the dwell's line at first_time_s
  double counter_at_first_rad = 0.0;  ///< psi_r on the dwell's line at first_time_s
};

/// A piece of the angle the output's harmonic fit took as its basis through a spinning dwell: from its
/// `first_sample`-th measured sample on (counted over the stretches in order), the counter platform's angle
/// psi_r = at_rad + rate_rad_s (t - t0_s) on the dwell's clock, gamma = -psi_r (rad, unwrapped as the output
/// had it). The reducer takes the counter encoder's line of its last rate window, and after a gap, until a
/// window has closed, each reading itself (one piece a sample, rate 0). The model terms that follow a
/// dwell's measured motion take the same angle (identify/model_terms.hpp, basis_counter_angle), so that data
/// and model are reduced by one operator when a drive's ripple bends the counter encoder's line window by
/// window.
struct BasisAngle {
  std::size_t first_sample = 0;
  double t0_s = 0.0, at_rad = 0.0, rate_rad_s = 0.0;
  double at(double t_s) const { return at_rad + rate_rad_s * (t_s - t0_s); }
};

/// What a dwell's steady run held and what of it was dropped, and why (docs/contract.md, data_quality).
struct DwellQuality {
  double run_start_s = 0.0, run_end_s = 0.0;  ///< the steady run, record time
  std::size_t rows = 0;                       ///< rows in the steady run
  std::size_t settle_rows = 0;                ///< dropped: in the settle interval
  std::size_t beyond_planned_rows = 0;        ///< dropped: after the planned duration
  std::size_t encoder_glitch_rows = 0;        ///< dropped: encoders left the line for a few rows
  /// dropped: the last ReduceOptions::leave_guard_s before the machine left the steady state
  std::size_t before_leaving_rows = 0;
  /// dropped: rows of the measured part whose increments have no known interval (a record with an increment
  /// column: the row after a gap or a lost row; Reducer::set_increments)
  std::size_t increments_dropped = 0;
  std::string ended;  ///< why the run ended
};

/// One measured dwell: a spinning dwell (rate, beta) or a static hold (beta, gamma).
struct Dwell {
  bool is_static = false;
  double planned_rate_rad_s = 0.0;  ///< the plan's rate this dwell was matched to
  /// The plan's counter rate offset this dwell was matched to (docs/physics.md section 15), rad/s: the
  /// counter platform turned at -rate + offset, gamma at rate - offset, and the revolutions are counted on
  /// gamma.
  double planned_counter_rate_offset_rad_s = 0.0;
  double beta_rad = 0.0;            ///< the plan's beta this dwell was matched to
  double measured_beta_rad = 0.0;   ///< mean position encoder reading
  std::vector<double> gammas_rad;   ///< the plan's gammas reduced here (one for a static hold)
  std::vector<int> position_index;  ///< per gamma: the plan's position index (1-based, plan/positions.hpp)
  double first_time_s = 0.0, last_time_s = 0.0;  ///< the measured part (after the settle interval)
  std::size_t samples = 0;                       ///< samples in the measured part
  std::size_t gaps = 0;  ///< breaks in the measured part: intervals longer than 1.5 planned sample intervals
  double sample_interval_s = 0.0;   ///< mean interval between samples
  AngleLine main;                   ///< theta(t), from the main-axis encoder (its first stretch's phase)
  AngleLine counter;                ///< psi_r(t), from the counter-platform encoder
  double planned_duration_s = 0.0;  ///< what the plan asked for the measured part
  /// The reduced output of the sensor, per gamma, in its output unit: deg/h for a gyro, g for an
  /// accelerometer.
  DwellValues output;
  /// The samples of the measured part, stretch by stretch: the grid on which the model terms are
  /// evaluated and reduced like the sensor's output. Empty: `samples` evenly spaced instants (time_of_sample)
  /// on the lines `main` and `counter` (a planned dwell, analysis/predict).
  std::vector<TimeStretch> stretches;
  /// The main axis' motion as its encoder measured it through the measured part (a spinning dwell of a
  /// record; empty otherwise): what the model terms follow where it departs from the line `main`
  /// (identify/model_terms.hpp, docs/calibration.md).
  MeasuredMotion measured;
  /// The output's basis angle through the measured part, piece by piece (a spinning dwell of a record; empty
  /// otherwise).
  std::vector<BasisAngle> basis_angle;
  DwellQuality quality;

  /// The i-th of `samples` evenly spaced instants of the measured part (a dwell without stretches).
  double time_of_sample(std::size_t i) const {
    return first_time_s + static_cast<double>(i) * sample_interval_s;
  }
};

/// A steady run of the record that gave no dwell, and why (for the message naming a planned position that
/// has none).
struct RejectedRun {
  double start_s = 0.0, end_s = 0.0;  ///< record time
  double main_rate_rad_s = 0.0;       ///< measured
  double counter_rate_rad_s = 0.0;    ///< measured (psi_r relative to the arm)
  double beta_deg = 0.0, gamma_deg = 0.0;
  bool is_static = false;
  std::string reason;
};

/// One reduced position, in the plan's order.
struct ReducedPosition {
  int index = 0;            ///< plan/positions.hpp numbering (docs/physics.md section 7 for the default test)
  double rate_rad_s = 0.0;  ///< planned rate
  double beta_rad = 0.0;    ///< planned beta
  double gamma_rad = 0.0;   ///< planned gamma
  double counter_rate_offset_rad_s = 0.0;  ///< planned counter rate offset (docs/physics.md section 15)
  /// The reduced output and its standard error, in the sensor's output unit: deg/h for a gyro, g for an
  /// accelerometer (results name them `mean` and `std_err` with their `unit`).
  double mean = 0.0;
  double std_err = 0.0;
  std::size_t samples = 0;
  /// Outliers rejected in the dwell this position is reduced from (one fit reduces all its gammas).
  std::size_t outliers = 0;
  int dwell = 0;       ///< index into Reduction::dwells
  int gamma_slot = 0;  ///< index into that dwell's gammas
  /// The output column (channel) it reduces: its index in the record's output columns
  /// (RecordLayout::output_columns(); 0 for a record of one sensor).
  int channel = 0;
};

/// The reduced position of plan position `p` measured by `dwell` (index `dwell_index` in the reduction) in
/// output column `channel` (whose values are dwell.output): its gamma's slot in the dwell, value, standard
/// error and sample count.
ReducedPosition reduced_position(const Position& p, const Dwell& dwell, int dwell_index, int channel = 0);

/// One output column's reduction of a record (a lone sensor's, or one channel of several read in one pass:
/// Reducer::finish_channels): its dwells, whose `output` holds this column's values, and every planned
/// position in order, each carrying the column as its `channel`.
struct Reduction {
  std::vector<Dwell> dwells;
  std::vector<ReducedPosition> positions;  ///< every position of the plan, in order
  std::vector<std::string> warnings;
  std::size_t samples_read = 0;  ///< rows of the record
  std::size_t samples_used = 0;  ///< rows in the measured parts of the dwells used
  std::size_t outliers = 0;      ///< of those, rejected as outliers in this column (and left out of its fit)
  std::size_t gaps = 0;          ///< breaks in the time series inside the dwells used (Dwell::gaps)
  std::size_t encoder_glitch_rows = 0;  ///< rows dropped inside the dwells used: encoders off their line
  /// A record with an increment column (Reducer::set_increments): the rows inside the dwells used that were
  /// left out of every column because an increment's interval was unknown (after a gap or a lost row; the
  /// record's first row). nullopt for a record without increments.
  std::optional<std::size_t> increments_dropped;
  std::vector<RejectedRun> rejected;  ///< steady runs that gave no dwell (the longest kRejectedKept)
};

/// The test the reducer expects: the configured plan and the rate that sizes a static hold when the plan
/// has none spinning (the configured centrifuge rate). One value, built once (docs/calibration.md).
struct PlannedTest {
  TestSpec spec;
  double reference_rate_rad_s = 0.0;
};

/// What a steady state of the machine matches in the plan: the one place where a found dwell is matched
/// to a planned position (by beta, gamma and the measured rates). Empty `why_not` when it matches.
struct PlanMatch {
  bool is_static = false;
  double planned_rate_rad_s = 0.0;
  /// The planned counter rate offset (docs/physics.md section 15): the counter platform turns at -rate +
  /// offset relative to the arm (at rate 0 at the offset alone: a plain rate table); 0 in a plain test.
  double planned_counter_rate_offset_rad_s = 0.0;
  double beta_rad = 0.0;
  double gamma_rad = 0.0;  ///< static holds
  std::string why_not;
};
PlanMatch match_to_plan(const TestSpec& plan, const ReduceOptions& options, double main_rate_rad_s,
                        double counter_rate_rad_s, double beta_deg, double gamma_deg);

/// Streaming reducer: push every sample of a record in order, then finish(). Memory is independent of the
/// record's length. Errors (gyrocal::Error) name the source and, where it applies, the time in the record.
class Reducer {
 public:
  /// plan: the configured test (rates, betas, gammas, revolutions, settle); source_name for messages.
  Reducer(const PlannedTest& plan, const ReduceOptions& options, std::string source_name);
  Reducer(const TestSpec& plan, const ReduceOptions& options, std::string source_name,
          double reference_rate_rad_s)
      : Reducer(PlannedTest{plan, reference_rate_rad_s}, options, std::move(source_name)) {}
  ~Reducer();
  /// Each dwell's accumulation runs on a thread of its own (reduce/accumulator_feed.hpp), unless this is
  /// called with false before the first push (a caller whose threads already keep every core busy, such as
  /// the Monte Carlo's trials). The numbers are the same either way.
  void set_threaded_accumulation(bool threaded);
  /// The record's rows hold `names.size()` output columns (RecordSample::outputs, 1 to
  /// limits::kMaxOutputColumns; one by default), each reduced beside the others in the one pass with its own
  /// outlier rule and standard errors; `names` name them in messages. Only before the first push.
  void set_output_columns(const std::vector<std::string>& names);
  /// The record holds an output column of increments (OutputForm::kIncrement, read divided by its interval:
  /// docs/records.md, "Increments"). Then a row of a dwell's measured part whose interval is unknown, the
  /// row after a gap (an interval longer than ReduceOptions::gap_intervals planned sample intervals: a break
  /// in the record or a lost row, whose increment covers an interval the stamps do not give) and the record's
  /// first row (no interval), is left out of every output column, so that every column and the model terms
  /// are reduced by one operator on the same samples; it is counted (DwellQuality::increments_dropped,
  /// Reduction::increments_dropped) and the next row starts a new stretch as after the gap. Only before the
  /// first push; false by default.
  void set_increments(bool increments);
  Reducer(const Reducer&) = delete;
  Reducer& operator=(const Reducer&) = delete;

  void push(const RecordSample& sample);
  /// push() for a caller that keeps the record's summary itself (reduce_record does) and hands it over with
  /// set_summary() before finish().
  void push_unsummarised(const RecordSample& sample);
  /// What the record holds, for finish()'s refusal (replaces what push() gathered).
  void set_summary(const RecordSummary& summary);
  /// The layout the record was read through (nullopt: gyrocal's own format), for the message of finish()
  /// only: it names the [record] key a unit mistake points to.
  void set_record_layout(const std::optional<RecordLayout>& layout);
  /// Match the dwells to the plan; an error if a planned position has no dwell. For a record of one output
  /// column (a reducer of several refuses it: finish_channels).
  Reduction finish();
  /// finish() for every output column (set_output_columns): one Reduction per column, in order, each with
  /// the same dwells (their `output` that column's values) and positions whose `channel` is the column.
  std::vector<Reduction> finish_channels();
  /// The dwells held so far: one a planned place (rate, counter rate offset, beta, a static hold's gamma),
  /// the longest of a record that repeats it (the first of equal length), so that memory does not grow with
  /// repeats; 0 after finish(), which moves them into the Reduction.
  std::size_t dwells_held() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// Reduce a whole record file (streaming; the rows are read ahead on a thread of their own, and each dwell's
/// accumulation runs on another, reduce/accumulator_feed.hpp). `observe`, when given, sees every batch of
/// rows, in order, on the caller's thread, before the reducer does (e.g. the output's range,
/// identify/misfit.hpp).
/// For a record of one output column (a reader of several is refused: reduce_record_channels).
Reduction reduce_record(RecordReader& reader, const TestSpec& plan, const ReduceOptions& options,
                        double reference_rate_rad_s,
                        const std::function<void(std::span<const RecordSample>)>& observe = {});
/// reduce_record for every output column the reader gives (RecordReader::output_count(), through a layout's
/// RecordLayout::outputs): one pass over the record, one Reduction per column in order (finish_channels).
std::vector<Reduction> reduce_record_channels(
    RecordReader& reader, const TestSpec& plan, const ReduceOptions& options, double reference_rate_rad_s,
    const std::function<void(std::span<const RecordSample>)>& observe = {});

}  // namespace gyrocal
