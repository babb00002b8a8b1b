// The gyro's model columns (omega_I and the drift regressors, exact and nominal; docs/physics.md sections 4,
// 5 and 15) and how a reduced position's columns become its PositionModelTerms; the reduction itself is the
// one per-dwell model route's (identify/dwell_model_route.hpp).
#include "gyrocal/identify/model_terms.hpp"

#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/dwell_model_route.hpp"
#include "gyrocal/model/nominal.hpp"

namespace gyrocal {

namespace {

// Columns: omega exact, nominal, seed (deg/h), then 10 exact and 10 nominal regressors, then the exact
// omega_O and omega_S (deg/h; docs/physics.md section 15).
constexpr int kFirstRegressor = 3;
constexpr int kOmegaO = kFirstRegressor + 2 * static_cast<int>(kNumGyroCoefficients);
constexpr int kColumns = kOmegaO + 2;

/// The model terms (kColumns values) of dwell d at joint state j, the encoders at the output's stamp; beta as
/// planned (reduce/reducer.cpp: an encoder's mean at rest is biased by up to half a count). The exact inputs
/// are those the output holds (sensed_inputs: the joints the acquisition's delay earlier); the nominal ones
/// are a perfect machine's and acquisition's.
void evaluate_model_terms(const CentrifugeModel& model, const Dwell& d, JointState j, double* v) {
  j.position_angle_rad = d.beta_rad;
  const SensorInputs exact = sensed_inputs(model, j);
  const double offset = d.planned_counter_rate_offset_rad_s;
  const NominalInputs nominal = nominal_inputs(model, j, false, offset);
  v[0] = exact.rate_rad_s.x() * kRadPerSecToDegPerHour;
  v[1] = nominal.omega_I_rad_s * kRadPerSecToDegPerHour;
  v[2] = nominal_inputs(model, j, true, offset).omega_I_rad_s * kRadPerSecToDegPerHour;
  v[kOmegaO] = exact.rate_rad_s.y() * kRadPerSecToDegPerHour;
  v[kOmegaO + 1] = exact.rate_rad_s.z() * kRadPerSecToDegPerHour;
  const auto re = drift_regressors(exact.specific_force_g);
  const auto rn = drift_regressors(Eigen::Vector3d(nominal.a_I_g, nominal.a_O_g, nominal.a_S_g));
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    v[kFirstRegressor + k] = re[k];
    v[kFirstRegressor + kNumGyroCoefficients + k] = rn[k];
  }
}

}  // namespace

std::vector<PositionModelTerms> reduce_model_terms(const Reduction& reduction, const CentrifugeModel& model,
                                                   const ReduceOptions& options,
                                                   std::size_t max_samples_per_dwell, ModelTermsRoute route,
                                                   std::vector<DwellModelTermsRoute>* routes) {
  DwellModelRoute gyro;
  gyro.columns = kColumns;
  // The rates (deg/h): omega exact, nominal, seed, omega_O, omega_S; the rest are regressors (g, g^2).
  gyro.rate_columns.assign(kColumns, false);
  for (int c = 0; c < kColumns; ++c)
    gyro.rate_columns[static_cast<std::size_t>(c)] = c < kFirstRegressor || c >= kOmegaO;
  // Where the route's choices differ by sensor, the gyro keeps those it had before the route was one: each
  // other choice moves its plans' or calibrations' numbers (the two closed forms agree to ~1e-11, not bit for
  // bit; the two strides take other samples).
  // Planned dwells (`gyrocal plan`) in the planned closed form, written for these columns (issue 17, item 3);
  // a prediction's long dwells on the arm-angle band's stride (kMaxModelSamplesPerDwell, issue 11, item 9);
  // no per-revolution fits: the gyro's fields hold no PeriodRow, so no dwell of its is levelled again from
  // them (identify/residual_levels.cpp reads a sensor's sensor_periods).
  gyro.planned_closed_form = true;
  gyro.stride_bound = ModelStrideBound::kArmAngleBand;
  const std::vector<DwellModelValues> per_dwell = reduce_dwells_model(
      reduction, model, options, max_samples_per_dwell, route, gyro,
      [&](const Dwell& d, const JointState& j, double* v) { evaluate_model_terms(model, d, j, v); });
  if (routes) *routes = dwell_routes(per_dwell);
  std::vector<PositionModelTerms> out;
  for (const ReducedPosition& p : reduction.positions) {
    const auto at = [&](int c) { return position_column(per_dwell, p, c); };
    PositionModelTerms ch;
    ch.omega_exact_deg_h = at(0);
    ch.omega_nominal_deg_h = at(1);
    ch.omega_seed_deg_h = at(2);
    ch.omega_O_exact_deg_h = at(kOmegaO);
    ch.omega_S_exact_deg_h = at(kOmegaO + 1);
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
      ch.regressors_exact[k] = at(kFirstRegressor + static_cast<int>(k));
      ch.regressors_nominal[k] = at(kFirstRegressor + static_cast<int>(kNumGyroCoefficients + k));
    }
    out.push_back(ch);
  }
  return out;
}

}  // namespace gyrocal
