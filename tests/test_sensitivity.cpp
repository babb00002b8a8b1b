// The seed's error study (docs/physics.md sections 8 and 10) on the default scenario: which machine error
// shifts which estimate, without and with compensation, exactly (noise-free).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/analysis/sensitivity.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/model/nominal.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/result/sensitivity_json.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/simulated_pipeline.hpp"

namespace gyrocal {
namespace {

constexpr std::size_t kNone = 0, kSeed = 1, kFull = 2;

bool sanitized() {
  return std::getenv("GYROCAL_SANITIZED") != nullptr;
}

Scenario study_scenario() {
  Scenario s = default_scenario();
  if (sanitized()) s.test.revolutions = 20;  // shifts are exact at any length; the test only runs faster
  return s;
}

const SensitivityResult& default_study() {
  static const SensitivityResult r = sensitivity_study(study_scenario());
  return r;
}

/// The row of `error`, harmonic and phase (deg).
const SensitivityRow& row(const std::string& error, int harmonic = 0, double phase_deg = 0.0) {
  for (const SensitivityRow& r : default_study().rows)
    if (r.term.error == error && r.term.harmonic == harmonic &&
        std::abs(r.term.phase_rad * kRadToDeg - phase_deg) < 1e-9)
      return r;
  throw std::runtime_error("no row " + error);
}

double shift(const SensitivityRow& r, std::size_t compensation, const std::string& name) {
  return r.closed_form[compensation].at(name);
}

const char* const kPrimaryUnaffected[] = {"dO", "dS", "dIS", "dIO"};

TEST(Sensitivity, EveryMachineErrorHasItsRows) {
  const SensitivityResult& r = default_study();
  // 12 scalars, 2 vectors x 3 components, 8 series x (harmonics 1, 2 at 0 and 90 deg), and the configured
  // terms: the counter wobbles' second harmonics at 20 and 70 deg add a row each, the main wobble's first
  // harmonic at 0 deg takes the place of its typical row.
  EXPECT_EQ(r.rows.size(), 12u + 6u + 8u * 4u + 2u);
  EXPECT_EQ(row("counter_wobble_x", 2, 20.0).value, 1.0);  // configured: its magnitude and phase
  EXPECT_FALSE(row("counter_wobble_x", 2, 20.0).typical);
  EXPECT_EQ(row("counter_perpendicularity_y").value, -2.0);
  EXPECT_TRUE(row("base_tilt_x").typical);
  EXPECT_EQ(row("lever_arm_O").term.unit, "m");
}

TEST(Sensitivity, SeedsFindingWithoutCompensation) {
  // Counter-platform perpendicularity shifts dI (through k1, its y part) and dOS (k2, its x part) by hundreds
  // of noise sigmas (thousands with the default plan; the sanitizer build studies a shorter one) and leaves
  // the other primary closed forms alone.
  const SensitivityRow& px = row("counter_perpendicularity_x");
  const SensitivityRow& py = row("counter_perpendicularity_y");
  const auto& sigma = default_study().closed_form_noise_std;
  EXPECT_GT(std::abs(shift(px, kNone, "dOS")), 100 * sigma.at("dOS"));
  EXPECT_GT(std::abs(shift(py, kNone, "dI")), 100 * sigma.at("dI"));
  for (const SensitivityRow* r : {&px, &py, &row("counter_rate_mismatch")})
    for (const char* name : kPrimaryUnaffected) EXPECT_LT(std::abs(shift(*r, kNone, name)), 1e-4) << name;
  // Delta omega enters omega_I as delta_omega * sin(beta) (docs/physics.md section 5): the 1 g form of dI,
  // which subtracts Omega_U, absorbs all of it; the centrifuge forms (positions at beta = 0, 180) see none.
  const SensitivityRow& dw = row("counter_rate_mismatch");
  EXPECT_NEAR(shift(dw, kNone, "dI_1g"), 2e-6 * kRadPerSecToDegPerHour, 1e-4);
  EXPECT_LT(std::abs(shift(dw, kNone, "dI")), 1e-4);
  EXPECT_LT(std::abs(shift(dw, kNone, "dOS")), 1e-4);
  EXPECT_NE(std::find(px.closed_form_matters[kNone].begin(), px.closed_form_matters[kNone].end(), "dOS"),
            px.closed_form_matters[kNone].end());
}

TEST(Sensitivity, PerpendicularityShiftAgreesWithTheFirstOrderClosedForm) {
  // docs/physics.md section 8: dOS = -[(W3 - W4) - (W7 - W8) + 4 k2 w] / (4 Ar). Uncompensated, the outputs
  // carry -k2 w, k2 w, k2 w, -k2 w at positions 3, 4, 7, 8 (section 7), so the estimate moves by k2 w / Ar,
  // with k2 = count_perp_x. Likewise dI = [(W1 - W2) - (W5 - W6) - 4 k1 w] / (-4 Ar) moves by -k1 w / Ar with
  // k1 = -count_perp_y.
  const Scenario s = study_scenario();
  const double w = s.test.rates_rad_s[0];
  const double ar = radial_level_g(s.site, s.centrifuge.radius_m, w);
  const double k2 = 3.0 * kArcsecToRad, k1 = 2.0 * kArcsecToRad;
  const double dos = k2 * w * kRadPerSecToDegPerHour / ar, di = -k1 * w * kRadPerSecToDegPerHour / ar;
  EXPECT_NEAR(shift(row("counter_perpendicularity_x"), kNone, "dOS"), dos, 0.01 * std::abs(dos));
  EXPECT_NEAR(shift(row("counter_perpendicularity_y"), kNone, "dI"), di, 0.01 * std::abs(di));
}

TEST(Sensitivity, SeedCompensationIsExactForPerpendicularityAndRateMismatchNotForWobble) {
  for (const char* error :
       {"counter_perpendicularity_x", "counter_perpendicularity_y", "counter_rate_mismatch"})
    for (const char* name : {"dI", "dOS"})
      EXPECT_LT(std::abs(shift(row(error), kSeed, name)), 1e-4) << error << " " << name;
  EXPECT_LT(std::abs(shift(row("counter_rate_mismatch"), kSeed, "dI_1g")), 1e-4);
  // A wobble's own rate n a w (docs/physics.md section 5) is not in the seed's terms: the configured second
  // harmonics still shift dI or dOS, by hundreds of sigmas (docs/physics.md section 8's -0.18 and -1.38).
  EXPECT_GT(std::abs(shift(row("counter_wobble_x", 2, 20.0), kSeed, "dI")), 0.1);
  EXPECT_GT(std::abs(shift(row("counter_wobble_y", 2, 70.0), kSeed, "dOS")), 0.1);
}

TEST(Sensitivity, FullCompensationRemovesEveryShift) {
  for (const SensitivityRow& r : default_study().rows) {
    for (const auto& [name, v] : r.closed_form[kFull]) EXPECT_LT(std::abs(v), 1e-4) << r.term.label() << name;
    for (const auto& [name, v] : r.least_squares[kFull])
      EXPECT_LT(std::abs(v), 1e-6) << r.term.label() << name;
    EXPECT_TRUE(r.least_squares_matters[kFull].empty()) << r.term.label();
  }
}

TEST(Sensitivity, FirstHarmonicMainWobbleActsLikeACounterPerpendicularity) {
  // docs/physics.md section 10: per arcsec, a first-harmonic main-axis wobble about x shifts dOS (cosine
  // part) or dI (sine part) as much as the counter platform's perpendicularity does, and the seed's
  // compensation, which knows only the counter platform, leaves it.
  const double dos_per_arcsec = shift(row("counter_perpendicularity_x"), kNone, "dOS") / 3.0;
  const double di_per_arcsec = shift(row("counter_perpendicularity_y"), kNone, "dI") / -2.0;
  const SensitivityRow& cosine = row("main_wobble_x", 1, 0.0);  // configured, 0.5 arcsec
  const SensitivityRow& sine = row("main_wobble_x", 1, 90.0);   // typical, 1 arcsec
  EXPECT_NEAR(shift(cosine, kNone, "dOS") / cosine.value, dos_per_arcsec, 0.02 * std::abs(dos_per_arcsec));
  EXPECT_NEAR(std::abs(shift(sine, kNone, "dI") / sine.value), std::abs(di_per_arcsec),
              0.02 * std::abs(di_per_arcsec));
  EXPECT_GT(std::abs(shift(cosine, kSeed, "dOS")), 0.1);
  for (const char* name : kPrimaryUnaffected) EXPECT_LT(std::abs(shift(cosine, kNone, name)), 1e-4) << name;
}

TEST(Sensitivity, FirstHarmonicCounterWobbleShiftsTheOneGFormOfDS) {
  // docs/physics.md section 10: k1 = -count_wobble_y(psi_r) with psi_r = -gamma makes k1 cos(gamma) w a
  // constant, which dS_1g = [(W1 + W2) - (W5 + W6) - 4 Omega_N] / 4 takes for a drift; the seed's terms
  // remove it.
  const SensitivityRow& r = row("counter_wobble_y", 1, 0.0);
  const auto& sigma = default_study().closed_form_noise_std;
  EXPECT_GT(std::abs(shift(r, kNone, "dS_1g")), 100 * sigma.at("dS_1g"));
  EXPECT_LT(std::abs(shift(r, kSeed, "dS_1g")), 1e-3);
  for (const char* name : {"dI", "dO", "dS", "dIS", "dIO", "dOS"})
    EXPECT_LT(std::abs(shift(r, kNone, name)), 1e-4) << name;
}

TEST(Sensitivity, JsonHasTheInterfaceKeys) {
  const nlohmann::json j = sensitivity_to_json(default_study());
  ASSERT_TRUE(j["rows"].is_array());
  const nlohmann::json& first = j["rows"][0];
  for (const char* key : {"error", "harmonic", "value", "unit", "shift", "least_squares"})
    EXPECT_TRUE(first.contains(key)) << key;
  for (const char* comp : {"none", "seed", "full"})
    for (const char* name : {"dI", "dO", "dS", "dIS", "dIO", "dOS", "dI_1g", "dO_1g", "dS_1g", "dIS_b",
                             "dII-dSS", "dOO-dSS", "dF+(1+Ar^2)dSS"})
      EXPECT_TRUE(first["shift"][comp].contains(name)) << comp << " " << name;
  EXPECT_EQ(first["error"], "base_tilt_x");  // the key without its unit suffix
  EXPECT_EQ(first["harmonic"], 0);
  EXPECT_TRUE(j["noise_std"].contains("dOS"));
}

TEST(Sensitivity, ResultDoesNotDependOnTheNumberOfThreads) {
  Scenario s = default_scenario();
  s.test.revolutions = 5;
  s.test.sample_rate_hz = 50;
  SensitivityOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const SensitivityResult a = sensitivity_study(s, one), b = sensitivity_study(s, two);
  ASSERT_EQ(a.rows.size(), b.rows.size());
  for (std::size_t i = 0; i < a.rows.size(); ++i)
    for (std::size_t c = 0; c < 3; ++c) {
      EXPECT_EQ(a.rows[i].closed_form[c], b.rows[i].closed_form[c]);
      EXPECT_EQ(a.rows[i].least_squares[c], b.rows[i].least_squares[c]);
    }
}

// ---- The rate errors of the gyro model drift+rate (docs/physics.md section 15) ----------------------------

/// The default machine and drift truth with the rate errors of issue 12 and counter rate offsets of both
/// signs at one speed (no compensation "self": the study stays quick), noise-free, short.
Scenario rate_platform_scenario() {
  Scenario s = default_scenario();
  s.noise = GyroNoise{};
  s.gyro_rate = {150.0, -25.0, 40.0};
  s.test.counter_rate_offsets_rad_s = {0.0, 0.25, -0.25};
  s.test.sample_rate_hz = 50.0;
  // Not shortened under the sanitizers: how much of the Earth rate's sweep a dwell at an offset holds
  // depends on its length, and with it the shift a misfit error leaves (see the tolerance below).
  s.test.revolutions = 8;
  s.test.settle_s = 1.0;
  return s;
}

/// e, dO, dS (ppm, arcsec) of a noise-free simulated record of `s`, reduced and identified by least squares
/// with the gyro model drift+rate and compensation none: the whole pipeline, not the study's prediction.
/// Without compensation the model does not fit a machine error exactly, so the estimate depends on the
/// weights: the record's positions are weighted as the study weights its planned ones (the configured
/// noise through the reduction operator), not by the scatter a noise-free record happens to show.
CalibrationResult simulate_and_calibrate(const Scenario& s) {
  Reduction reduction = testing::simulate_and_reduce(s, std::nullopt);
  set_predicted_std_errors(reduction, s.noise, s.test.sample_rate_hz);
  CalibrationOptions o;
  o.gyro_model = GyroModel::kDriftRate;
  o.compensation = Compensation::kNone;
  return identify(reduction, reduce_model_terms(reduction, s.model(), o.reduce), s.model(), o);
}

TEST(SensitivityRateTerms, ShiftOfScaleFactorAndMisalignmentIsTheSimulatedFiniteDifference) {
  // Each machine error's effect on e and dS, as the study predicts it, against an independent route: a
  // noise-free record simulated with and without that error alone (the study's base has no machine error),
  // each reduced and calibrated with drift+rate, and the difference of the estimates. Without compensation
  // the counter platform's perpendicularity about y turns the offsets' rotation off Up (e moves by ppm), and
  // a mount misalignment about O tilts I toward S (dS moves by the misalignment itself).
  const Scenario s = rate_platform_scenario();
  SensitivityOptions options;
  options.calibration.gyro_model = GyroModel::kDriftRate;
  const SensitivityResult study = sensitivity_study(s, options);
  EXPECT_EQ(study.gyro_model, GyroModel::kDriftRate);
  EXPECT_EQ(study.units.at("scale_factor_error_ppm"), "ppm");
  EXPECT_EQ(study.units.at("input_axis_misalignment_S_arcsec"), "arcsec");

  Scenario base = s;
  base.errors = CentrifugeErrors{};
  const CalibrationResult without = simulate_and_calibrate(base);
  ASSERT_TRUE(without.coefficients[kNumGyroCoefficients].identifiable &&
              without.coefficients[kNumGyroCoefficients + 2].identifiable);
  EXPECT_NEAR(without.coefficients[kNumGyroCoefficients].value, 150.0, 1e-2);

  struct Case {
    const char* error;
    void (*add)(CentrifugeErrors&, const Scenario&);
    std::size_t moves;  ///< the rate error it was chosen for: it moves it by at least `by`
    double by;
    double tolerance;  ///< relative
  };
  const Case cases[] = {
      {"counter_perpendicularity_y",
       [](CentrifugeErrors& e, const Scenario& sc) {
         e.counter_perpendicularity_y_rad = sc.errors.counter_perpendicularity_y_rad;  // configured: -2"
       },
       0, 0.5, 0.06},
      {"counter_rate_mismatch",
       [](CentrifugeErrors& e, const Scenario& sc) {
         e.counter_rate_mismatch_rad_s = sc.errors.counter_rate_mismatch_rad_s;  // configured: 2e-6 rad/s
       },
       0, 0.1, 0.06},
      {"mount_misalignment_O",
       [](CentrifugeErrors& e, const Scenario&) { e.mount_misalignment_rad.y() = kArcsecToRad; },  // typical
       2, 0.5, 0.01},
  };
  for (const Case& c : cases) {
    const SensitivityRow* row = nullptr;
    for (const SensitivityRow& r : study.rows)
      if (r.term.error == c.error && r.term.harmonic == 0) row = &r;
    ASSERT_NE(row, nullptr) << c.error;
    Scenario with = base;
    c.add(with.errors, s);
    const CalibrationResult r = simulate_and_calibrate(with);
    ASSERT_TRUE(r.coefficients[kNumGyroCoefficients].identifiable &&
                r.coefficients[kNumGyroCoefficients + 2].identifiable)
        << c.error;
    for (std::size_t k : {std::size_t{0}, std::size_t{2}}) {
      const std::string name(kRateTermNames[k]);
      const double finite_difference = r.coefficients[kNumGyroCoefficients + k].value -
                                       without.coefficients[kNumGyroCoefficients + k].value;
      const double predicted = row->least_squares[kNone].at(name);
      // The tolerance: 2e-3 ppm or arcsec (a noise-free record recovers e and dS to about 1e-3) and a share
      // of the shift: 1 % for an error the model absorbs exactly (a mount misalignment is an input-axis
      // misalignment), 6 % for one it does not fit without compensation. Such an error's trace at an offset
      // rides on the Earth rate's sweep through the dwell (not a harmonic of gamma), whose average depends on
      // where the dwell begins; a record's dwell begins where the reducer finds the machine steady, which may
      // be before the planned interval (docs/rate_platform.md), and the study's shifts are the planned
      // intervals' (3.5-4 % apart here).
      EXPECT_NEAR(predicted, finite_difference, c.tolerance * std::abs(finite_difference) + 2e-3)
          << c.error << " " << name;
      if (k == c.moves) {
        EXPECT_GT(std::abs(finite_difference), c.by) << c.error << " " << name;
      }
    }
  }
}

TEST(SensitivityRateTerms, ARateErrorThePlanCannotIdentifyIsNamedWithItsReasonNotGivenAShift) {
  // The default plan has no counter rate offsets: only the Earth rate's horizontal part reaches O, and the
  // machine without errors (the study's base) cannot separate dO (docs/rate_platform.md). It must be said,
  // with the reason, and carry no shift (a number there would be meaningless).
  Scenario s = default_scenario();
  s.test.revolutions = 5;
  s.test.sample_rate_hz = 50;
  SensitivityOptions options;
  options.calibration.gyro_model = GyroModel::kDriftRate;
  const SensitivityResult r = sensitivity_study(s, options);
  const std::string o = "input_axis_misalignment_O_arcsec";
  ASSERT_EQ(r.not_identifiable.count(o), 1u);
  EXPECT_NE(r.not_identifiable.at(o).find("Earth rate"), std::string::npos) << r.not_identifiable.at(o);
  for (const SensitivityRow& row : r.rows)
    for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(row.least_squares[c].count(o), 0u) << row.term.error;
  EXPECT_EQ(r.least_squares_noise_std.count(o), 0u);
  const nlohmann::json j = sensitivity_to_json(r);
  EXPECT_EQ(j["gyro_model"], "drift+rate");
  EXPECT_EQ(j["not_identifiable"][o], r.not_identifiable.at(o));
  EXPECT_FALSE(j["rows"][0]["least_squares"]["full"].contains(o));
  // e and dS are identifiable here (barely: through the Earth rate alone), and have their shifts.
  EXPECT_TRUE(j["rows"][0]["least_squares"]["full"].contains("input_axis_misalignment_S_arcsec"));
}

}  // namespace
}  // namespace gyrocal
