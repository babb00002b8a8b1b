#pragma once
// The model's side of each reduced position: omega_I and the drift regressors, exact (docs/physics.md section
// 4) and nominal (section 5), evaluated on each dwell's samples and reduced by the very operator that reduced
// the gyro output (reduce/dwell_accumulator.hpp), by the one per-dwell model route every sensor takes
// (identify/dwell_model_route.hpp, which this header includes).
#include <array>
#include <functional>
#include <vector>

#include "gyrocal/identify/dwell_model_route.hpp"
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
