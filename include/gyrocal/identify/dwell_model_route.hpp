#pragma once
// One per-dwell route for the model's side of each reduced position (issue 26, item 1), for any sensor: the
// model's columns (the gyro's 25, identify/model_terms.hpp; a sensor's design row, identify/
// sensor_model_terms.hpp) evaluated at a dwell's joints and reduced by the very operator that reduced the
// output (reduce/dwell_accumulator.hpp), by the cheapest route that gives the same sums: a planned dwell's
// closed form (identify/planned_model_terms.hpp), the columns' Fourier series in the two joint angles summed
// in closed form (reduce_dwell_by_fourier), or sample by sample (every sample, or on a stride where one is
// configured), on the dwell's constant-rate lines or on its measured motion where the drive's rate ripples
// (follows_measured_rate). The callers give only their columns' evaluator and read the values per position.
#include <cstddef>
#include <functional>
#include <vector>

#include <Eigen/Dense>

#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/reduce/dwell_accumulator.hpp"
#include "gyrocal/reduce/reducer.hpp"

namespace gyrocal {

/// Most model evaluations per spinning dwell for a prediction (`gyrocal plan`, issue 11, item 9): beyond
/// ReduceOptions::model_samples_per_revolution * revolutions = this, the model terms are evaluated on a
/// stride longer than a revolution, chosen so that the arm angle advances by 2 pi / 40 .. 2 pi / 10 (mod 2
/// pi) from one evaluation to the next: a uniform sampling of gamma (no harmonic up to 9 aliases onto the
/// fit's) spread over the whole dwell (the drift). The cost of the model terms then does not grow with the
/// test's length; docs/calibration.md states the error.
inline constexpr std::size_t kMaxModelSamplesPerDwell = 32768;

/// How the model terms of a dwell are reduced when every sample is asked for (ReduceOptions::
/// model_samples_per_revolution = 0).
enum class ModelTermsRoute {
  /// The model terms as a Fourier series in the two joint angles, summed over the samples in closed form,
  /// when
  /// the series' check holds (docs/calibration.md, "The model's side of each position"); otherwise every
  /// sample. The default.
  kExact,
  kEverySample,  ///< the model evaluated at every sample (the reference the closed forms are tested against)
};

/// What was done for one dwell (reduce_model_terms' `routes`).
struct DwellModelTermsRoute {
  bool fourier = false;  ///< the closed forms were used
  /// The joints followed the dwell's measured motion (Dwell::measured; every sample, no closed form).
  bool measured_rate = false;
  int harmonics = 0;  ///< H of the Fourier series tried last (0: not tried)
  /// Per model term column (the gyro's: omega exact, nominal, seed, 10 exact and 10 nominal regressors,
  /// omega_O, omega_S; another sensor's: its design row's known part, then its regressors): the sum of |C_nm|
  /// over the outer quarter of the band (max(|n|, |m|) > 3H/4), and over all of it, in the column's unit.
  std::vector<double> outer_tail, scale;
  /// Per gamma of the dwell: the reduction operator's white-noise gain sum_i w_i^2 (DwellAccumulator::
  /// white_noise_gain); sqrt(samples x gain) bounds the operator's L1 norm sum_i |w_i|.
  std::vector<double> operator_gain;
};

/// A dwell's model terms (`columns` values into v) with the main axis at main_rad and the counter platform at
/// counter_rad, rad, the other joints as the dwell has them (its lines' rates, beta as planned).
using DwellModelTermsEvaluator = std::function<void(double main_rad, double counter_rad, double* v)>;

/// The sums the reduction operator takes of a dwell's model terms, from their Fourier series in the two joint
/// angles summed over its samples in closed form (docs/calibration.md, "The model's side of each position"),
/// added to `acc` (built with `columns` columns) when the series' check holds for every column; false when it
/// does not or every sample costs less (`acc` untouched: the caller then takes every sample). The check's
/// floor is the rate's rounding where rate_column[c] (deg/h), a regressor's otherwise. `route` says what was
/// tried: H, the outer band's and the whole series' sums of |C_nm| per column, the operator's gains.
/// (identify/fourier_model_terms.cpp)
/// interval_s > 0: the columns' means over each sample's interval [t - interval_s, t] are summed instead of
/// their values at t (an increment's model, docs/records.md "Increments"): each term C_nm e^{j (n theta + m
/// psi)} times interval_mean_factor(n w_main + m w_counter, interval_s) (record/increments.hpp), exact for
/// the dwell's constant rates.
bool reduce_dwell_by_fourier(const CentrifugeModel& model, const Dwell& d, const ReduceOptions& options,
                             DwellAccumulator& acc, int columns, const std::vector<bool>& rate_column,
                             const DwellModelTermsEvaluator& evaluate, DwellModelTermsRoute& route,
                             double interval_s = 0.0);

/// The harmonics H the Fourier route tries first for `model`'s configured errors: 8 x their highest harmonic
/// + 4, at least 12 (it doubles H once where the series' check fails).
int fourier_harmonics(const CentrifugeModel& model);

/// Below this, in g, what a dwell's constant-rate line misses of the specific force (measured_rate_effect_g)
/// is not worth following the measured motion: 1e-4 ug, the exactness asked of a noise-free accelerometer
/// calibration, and far above the spline's rounding on a noise-free record.
inline constexpr double kMeasuredRateFloorG = 1e-10;

/// What dwell d's constant-rate line misses of the specific force at the arm's effective radius R, g, by the
/// measured motion's largest departures from it (reduce/measured_rate.hpp): (2 |w| max|dw| + max|dw/dt| +
/// w^2 max|dtheta|) R / g0. The centripetal force is first order in the rate: a ripple of 5e-5 at 12 g moves
/// it by 1.2 mg.
double measured_rate_effect_g(const CentrifugeModel& model, const Dwell& d);

/// The joints the model terms are evaluated at for the i-th sample of stretch `stretch` of a record's dwell d
/// that follows its measured motion (d.measured, reduce/measured_rate.hpp): the main axis' angle, rate and
/// acceleration from the spline; the counter platform turns back what the arm departs from its line (the
/// heading stays on its line), beta as planned.
JointState measured_joints(const Dwell& d, std::size_t stretch, std::size_t i);

/// The output's basis angle replayed sample by sample (Dwell::basis_angle): psi_r, rad, of the measured
/// samples in their order (the stretches' samples one after the other), at their times on the dwell's clock.
class BasisAngleCursor {
 public:
  explicit BasisAngleCursor(const std::vector<BasisAngle>& pieces) : pieces_(pieces) {}
  double at(std::size_t sample, double t_s) {
    while (next_ < pieces_.size() && pieces_[next_].first_sample <= sample) ++next_;
    return next_ == 0 ? 0.0 : pieces_[next_ - 1].at(t_s);
  }

 private:
  const std::vector<BasisAngle>& pieces_;
  std::size_t next_ = 0;
};

/// The samples the output's reduction left out as outliers (DwellValues::outlier_samples, ascending),
/// asked for in ascending order of their numbers in the dwell.
class LeftOutSamples {
 public:
  explicit LeftOutSamples(const std::vector<std::size_t>& samples) : samples_(samples) {}
  bool contains(std::size_t sample) {
    while (next_ < samples_.size() && samples_[next_] < sample) ++next_;
    return next_ < samples_.size() && samples_[next_] == sample;
  }

 private:
  const std::vector<std::size_t>& samples_;
  std::size_t next_ = 0;
};

/// Whether dwell d's model terms follow its measured motion (reduce/measured_rate.hpp) rather than its line
/// (docs/calibration.md, "The rate the channels follow"): the spline departs from the line beyond the
/// readings' scatter, the encoder resolves the change, and measured_rate_effect_g exceeds
/// kMeasuredRateFloorG. Every sensor's model terms (reduce_dwell_model) follow it alike.
bool follows_measured_rate(const CentrifugeModel& model, const Dwell& d);

/// How a dwell's evaluations are spread where a bound on them is given (reduce_dwell_model's
/// max_samples_per_dwell > 0) and the configured stride (ReduceOptions::model_samples_per_revolution) would
/// exceed it.
enum class ModelStrideBound {
  /// Spinning dwells only: a stride longer than a revolution whose arm-angle step lies between 2 pi / 40 and
  /// 2 pi / 10 (mod 2 pi), so that no harmonic up to 9 aliases onto the fit's (kMaxModelSamplesPerDwell).
  kArmAngleBand,
  /// Every dwell, static holds too: the stride at least ceil(samples / bound), whatever arm-angle step it
  /// makes.
  kEvenSpread,
};

/// What one sensor's model columns are and which of the route's choices it takes. The choices differ by
/// sensor today, each kept as it was so that no result changes (the callers say why).
struct DwellModelRoute {
  int columns = 0;                 ///< how many model columns the evaluator writes
  std::vector<bool> rate_columns;  ///< per column: a rate (deg/h; the Fourier check's rate floor) or not
  /// A planned dwell (no stretches) reduced by the harmonic fit or a static mean, every sample asked for or
  /// a bound given (max_samples_per_dwell > 0), by identify/planned_model_terms.hpp's closed form (equal to
  /// the every-sample sums to ~1e-11) before the Fourier route is tried.
  bool planned_closed_form = false;
  ModelStrideBound stride_bound = ModelStrideBound::kArmAngleBand;  ///< see ModelStrideBound
  /// Where the dwell follows its measured motion and is reduced by the harmonic fit: the columns also
  /// reduced revolution by revolution by the output's per-revolution fit (DwellModelValues::revolutions).
  bool per_revolution = false;
  /// The columns are the means over each sample's interval [t - dt, t], dt the dwell's sample interval
  /// (Dwell::sample_interval_s), not their values at t: the model of an output written as increments
  /// (docs/records.md, "Increments"). The Fourier route multiplies each term by its interval factor; every
  /// sample takes the Gauss-Legendre rule (record/increments.hpp) of enough nodes for 1e-13 at twice the
  /// Fourier route's first band, fourier_harmonics x (|main rate| + |counter rate|); the planned closed form
  /// is not taken.
  bool interval_mean = false;
};

/// A sensor's model columns (DwellModelRoute::columns values into `columns`) at joint state `j` of dwell
/// `d` (the encoders at the output's stamp; j's beta is the dwell's planned one).
using JointModelColumns = std::function<void(const Dwell& d, const JointState& j, double* columns)>;

/// One revolution's reduced columns of a dwell that follows its measured motion (DwellModelRoute::
/// per_revolution): `index` the revolution of the output's basis angle from the dwell's first sample,
/// `values` (gamma x column) the revolution's harmonic fit at the dwell's gammas.
struct RevolutionModelValues {
  int index = 0;
  Eigen::MatrixXd values;
};

/// A dwell's reduced model columns and how they were reduced.
struct DwellModelValues {
  std::vector<DwellValues> columns;  ///< per column: one value per gamma of the dwell
  DwellModelTermsRoute route;        ///< what was done
  /// Per revolution, where DwellModelRoute::per_revolution and the dwell follows its measured motion (only
  /// revolutions with two samples per fit parameter); empty otherwise.
  std::vector<RevolutionModelValues> revolutions;
};

/// The model columns of dwell `d` (`route.columns` of them, written by `evaluate`) reduced by its output's
/// operator (the heading's sweep at a counter rate offset included): by the planned closed form where `route`
/// takes it and it applies, else, where every sample is asked for
/// (ReduceOptions::model_samples_per_revolution 0) and `closed_forms` is kExact, by the Fourier closed forms
/// when the dwell stays on its lines and the series' check holds, else sample by sample (every sample, or the
/// configured stride, bounded by `max_samples_per_dwell` > 0 as route.stride_bound says), the joints on the
/// dwell's lines or, where it follows its measured motion, measured_joints with the output's own basis angle
/// and its outliers left out.
DwellModelValues reduce_dwell_model(const CentrifugeModel& model, const Dwell& d,
                                    const ReduceOptions& options, std::size_t max_samples_per_dwell,
                                    ModelTermsRoute closed_forms, const DwellModelRoute& route,
                                    const JointModelColumns& evaluate);

/// reduce_dwell_model for every dwell of `reduction`, in its order (the dwells in parallel, the same numbers
/// for any number of threads).
std::vector<DwellModelValues> reduce_dwells_model(const Reduction& reduction, const CentrifugeModel& model,
                                                  const ReduceOptions& options,
                                                  std::size_t max_samples_per_dwell,
                                                  ModelTermsRoute closed_forms, const DwellModelRoute& route,
                                                  const JointModelColumns& evaluate);

/// Column `column` of reduced position `p` (its dwell's value at its gamma) from reduce_dwells_model's
/// result.
inline double position_column(const std::vector<DwellModelValues>& dwells, const ReducedPosition& p,
                              int column) {
  return dwells[static_cast<std::size_t>(p.dwell)]
      .columns[static_cast<std::size_t>(column)]
      .value[static_cast<std::size_t>(p.gamma_slot)];
}

/// The routes of reduce_dwells_model's result, dwell by dwell (reduce_model_terms' `routes`).
std::vector<DwellModelTermsRoute> dwell_routes(const std::vector<DwellModelValues>& dwells);

}  // namespace gyrocal
