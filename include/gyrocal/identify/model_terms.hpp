#pragma once
// The model's side of each reduced position: omega_I and the drift regressors, exact (docs/physics.md section
// 4) and nominal (section 5), evaluated on each dwell's samples and reduced by the very operator that reduced
// the gyro output (reduce/dwell_accumulator.hpp).
#include <array>
#include <functional>
#include <vector>

#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/model/gyro.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/sensor/sensor_model.hpp"

namespace gyrocal {

/// What is subtracted from the measurements before identification (docs/physics.md section 8).
enum class Compensation {
  kNone,  ///< nothing known of the machine's errors: nominal inputs of a perfect machine
  kSeed,  ///< the seed's terms (k1 cos g - k2 sin g) w cos b + dw sin b from the configured errors
  kFull,  ///< omega_I(exact) - omega_I(nominal) from every configured error; exact regressors
};

/// Reduced model terms at one position.
struct PositionModelTerms {
  double omega_exact_deg_h = 0.0;    ///< omega_I of the exact model, deg/h
  double omega_nominal_deg_h = 0.0;  ///< omega_I of section 5 for a perfect machine, deg/h
  double omega_seed_deg_h = 0.0;     ///< omega_I of section 5 with the seed's k1, k2, dw, deg/h
  /// omega_O and omega_S of the exact model, deg/h: what the input axis' misalignments toward O and S sense
  /// (docs/physics.md section 15).
  double omega_O_exact_deg_h = 0.0;
  double omega_S_exact_deg_h = 0.0;
  std::array<double, kNumGyroCoefficients> regressors_exact{};    ///< eq. 6's regressors at the exact f
  std::array<double, kNumGyroCoefficients> regressors_nominal{};  ///< at the nominal f of section 5
  /// A sensor other than the gyro (identify/sensor_model_terms.hpp): its design row (known part and the
  /// regressors of its products) at the exact inputs, reduced by the same operator as its output. The gyro's
  /// fields above are then zero. Size 0 for the gyro.
  DesignRow sensor_exact;
  /// A sensor's dwell that follows its measured motion (follows_measured_rate): the design row reduced
  /// revolution by revolution as the output's scatter reduces it (the revolution's harmonic fit at this
  /// position's gamma; `index` the revolution of the output's basis angle from the dwell's first sample),
  /// so that identify takes the scatter of the output minus the model between revolutions. Empty otherwise:
  /// on the dwell's lines the model is the same every revolution.
  struct PeriodRow {
    int index = 0;
    DesignRow row;
  };
  std::vector<PeriodRow> sensor_periods;

  /// The omega_I the compensation assumes, deg/h.
  double omega_deg_h(Compensation c) const {
    return c == Compensation::kFull   ? omega_exact_deg_h
           : c == Compensation::kSeed ? omega_seed_deg_h
                                      : omega_nominal_deg_h;
  }
  /// The regressors the compensation assumes: exact with full compensation, nominal otherwise.
  const std::array<double, kNumGyroCoefficients>& regressors(Compensation c) const {
    return c == Compensation::kFull ? regressors_exact : regressors_nominal;
  }
};

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
bool reduce_dwell_by_fourier(const CentrifugeModel& model, const Dwell& d, const ReduceOptions& options,
                             DwellAccumulator& acc, int columns, const std::vector<bool>& rate_column,
                             const DwellModelTermsEvaluator& evaluate, DwellModelTermsRoute& route);

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
/// kMeasuredRateFloorG. The gyro's model terms (reduce_model_terms) and a sensor's
/// (identify/sensor_model_terms.hpp) follow it alike.
bool follows_measured_rate(const CentrifugeModel& model, const Dwell& d);

/// Model terms of every position of `reduction`, in its order, for `model`. `max_samples_per_dwell` > 0
/// bounds the model evaluations of a spinning dwell (above) where a stride is configured; 0 (a calibration)
/// evaluates ReduceOptions::model_samples_per_revolution per revolution, however many revolutions. A dwell
/// without stretches (a planned one) reduced by the harmonic fit or a static mean, with every sample asked
/// for (model_samples_per_revolution 0) or a bound, is summed in closed form at a cost independent of its
/// length (identify/planned_model_terms.hpp; equal to the every-sample sum to ~1e-11). A record's dwell, with
/// every sample asked for, goes by `route` (above); `routes`, when given, receives per dwell what was done.
std::vector<PositionModelTerms> reduce_model_terms(const Reduction& reduction, const CentrifugeModel& model,
                                                   const ReduceOptions& options,
                                                   std::size_t max_samples_per_dwell = 0,
                                                   ModelTermsRoute route = ModelTermsRoute::kExact,
                                                   std::vector<DwellModelTermsRoute>* routes = nullptr);

}  // namespace gyrocal
