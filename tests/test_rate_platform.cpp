// The machine as a rate table (docs/physics.md section 15, issue 12): counter rate offsets in the exact
// model, the timeline and the reducer; the gyro model drift+rate (scale-factor error, input-axis
// misalignments) identified by least squares beside the ten drift coefficients.
#include <cmath>
#include <cstdlib>
#include <string>

#include <fmt/format.h>

#include <gtest/gtest.h>

#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/plan/positions.hpp"
#include "gyrocal/plan/timeline.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/simulated_pipeline.hpp"

namespace gyrocal {
namespace {

bool sanitized() {
  return std::getenv("GYROCAL_SANITIZED") != nullptr;
}

using testing::Pipeline;
using testing::run;

CalibrationResult identify_with(const Scenario& s, const Pipeline& p, GyroModel g,
                                Method m = Method::kLeastSquares) {
  CalibrationOptions o;
  o.method = m;
  o.gyro_model = g;
  return identify(p.reduction, p.model_terms, s.model(), o);
}

/// The default scenario (its machine errors and drift truth) with the rate errors of issue 12 and offsets of
/// both signs at two speeds, noise-free, short.
Scenario rate_platform_scenario() {
  Scenario s = default_scenario();
  s.noise = GyroNoise{};
  s.gyro_rate = {150.0, -25.0, 40.0};
  s.test.rates_rad_s = {9.9, 4.95};
  s.test.counter_rate_offsets_rad_s = {0.0, 0.25, -0.25};
  s.test.sample_rate_hz = 50.0;
  s.test.revolutions = sanitized() ? 6 : 8;  // at least 5: the scatter at an offset has 4 parameters
  s.test.settle_s = 1.0;
  return s;
}

bool has_warning(const CalibrationResult& r, const std::string& part) {
  for (const std::string& w : r.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

// ----------------------------------------------------------------------------------------------------------
// The exact model.

TEST(RatePlatformModel, AnOffsetTurnsThePlatformAsARateMismatchOfTheSameSize) {
  // docs/physics.md section 15: the exact model carries the offset as it carries delta omega. A machine with
  // delta omega = 0.25 rad/s and no offset is the same motion as a perfect one commanded at offset 0.25.
  Scenario s = default_scenario();
  const double offset = 0.25;
  CentrifugeErrors with_mismatch = s.errors;
  with_mismatch.counter_rate_mismatch_rad_s += offset;
  const CentrifugeModel commanded = s.model();
  const CentrifugeModel mismatched(s.site, s.centrifuge, with_mismatch);
  for (double t : {0.0, 0.37, 5.2, 31.9})
    for (double beta : {0.0, kPi / 2, 2.0}) {
      const SensorInputs a = exact_inputs(commanded, spinning_joint_state(commanded, 9.9, beta, t, offset));
      const SensorInputs b = exact_inputs(mismatched, spinning_joint_state(mismatched, 9.9, beta, t));
      EXPECT_NEAR((a.rate_rad_s - b.rate_rad_s).norm(), 0.0, 1e-12) << t;
      EXPECT_NEAR((a.specific_force_g - b.specific_force_g).norm(), 0.0, 1e-9) << t;
    }
}

TEST(RatePlatformModel, ACounterRateIsTheFiniteDifferenceOfItsAngleAndARateTableSensesItsRate) {
  const Scenario s = default_scenario();
  const CentrifugeModel m = s.model();
  const double h = 1e-4;
  for (double offset : {0.5, -1.0}) {
    const JointState j = spinning_joint_state(m, 9.9, 0.0, 3.0, offset);
    const double fd = (spinning_joint_state(m, 9.9, 0.0, 3.0 + h, offset).counter_angle_rad -
                       spinning_joint_state(m, 9.9, 0.0, 3.0 - h, offset).counter_angle_rad) /
                      (2 * h);
    EXPECT_NEAR(j.counter_rate_rad_s, fd, 1e-8);
    EXPECT_NEAR(fd, -9.9 + offset + s.errors.counter_rate_mismatch_rad_s, 1e-8);
  }
  // A perfect machine, main axis stopped, platform at offset W: with I up (beta = 90 deg) the gyro senses
  // W + we sin(lat) on I; with S up (beta = 0) the same on S and nothing of W on I.
  const CentrifugeModel perfect(s.site, s.centrifuge, CentrifugeErrors{});
  const double up = s.site.earth_rate_rad_s * std::sin(s.site.latitude_rad);
  for (double offset : {0.5, -1.0})
    for (double t : {0.0, 2.0, 7.5}) {
      const SensorInputs i_up = exact_inputs(perfect, spinning_joint_state(perfect, 0.0, kPi / 2, t, offset));
      EXPECT_NEAR(i_up.rate_rad_s.x(), offset + up, 1e-12);
      const SensorInputs s_up = exact_inputs(perfect, spinning_joint_state(perfect, 0.0, 0.0, t, offset));
      EXPECT_NEAR(s_up.rate_rad_s.z(), offset + up, 1e-12);
      EXPECT_LT(std::abs(s_up.rate_rad_s.x()), s.site.earth_rate_rad_s * 1.0000001);
    }
}

TEST(RatePlatformModel, TheSensedRateCarriesScaleFactorAndMisalignments) {
  // (1 + e)(wI + dO wO + dS wS), written out with independent constants.
  const GyroRateErrors e{150.0, -25.0, 40.0};
  const Eigen::Vector3d w(0.3, -0.2, 0.5);
  const double arcsec = 3.14159265358979323846 / 648000.0;
  const double expected = (1 + 150e-6) * (0.3 + (-25 * arcsec) * (-0.2) + 40 * arcsec * 0.5) * 180.0 /
                          3.14159265358979323846 * 3600.0;
  EXPECT_NEAR(sensed_rate_deg_h(e, w), expected, 1e-9);
  EXPECT_EQ(sensed_rate_deg_h(GyroRateErrors{}, w), w.x() * kRadPerSecToDegPerHour);
}

// ----------------------------------------------------------------------------------------------------------
// The timeline and the reducer.

TEST(RatePlatformTimeline, NoJumpInAnyAngleOrRateAtAnOffsetChange) {
  Scenario s = default_scenario();
  s.errors = CentrifugeErrors{};  // delta omega 0: the servo law holds everywhere, no step of delta omega
  s.test.rates_rad_s = {9.9, 0.0};
  s.test.counter_rate_offsets_rad_s = {0.0, 0.25, -0.25};
  s.test.beta_rad = {0.0, kPi / 2};
  s.test.revolutions = 2;
  s.test.settle_s = 0.5;
  const Timeline tl = make_timeline(s.test, s.model());
  int offset_ramps = 0;
  for (const Segment& seg : tl.segments) offset_ramps += seg.kind == SegmentKind::kOffsetRamp;
  EXPECT_GE(offset_ramps, 4);
  // Finite differences across every segment boundary: angles continuous (their rate times the step), rates
  // continuous (their acceleration times the step).
  const double h = 1e-6;
  for (std::size_t k = 1; k < tl.segments.size(); ++k) {
    const double t = tl.segments[k].start_s;
    const JointState a = joint_state_at(tl, t - h), b = joint_state_at(tl, t + h);
    const std::string at = fmt::format("at t = {} s (segment {})", t, k);
    EXPECT_NEAR(b.main_angle_rad - a.main_angle_rad, 2 * h * b.main_rate_rad_s, 1e-8) << at;
    EXPECT_NEAR(b.counter_angle_rad - a.counter_angle_rad, 2 * h * b.counter_rate_rad_s, 1e-8) << at;
    EXPECT_NEAR(b.position_angle_rad - a.position_angle_rad, 2 * h * b.position_rate_rad_s, 1e-8) << at;
    EXPECT_NEAR(b.main_rate_rad_s, a.main_rate_rad_s, 1e-5) << at;
    EXPECT_NEAR(b.counter_rate_rad_s, a.counter_rate_rad_s, 1e-5) << at;
    EXPECT_NEAR(b.position_rate_rad_s, a.position_rate_rad_s, 1e-5) << at;
  }
  // In every dwell the counter platform turns at -rate + offset, the platform's heading at the offset.
  for (const MeasurementInterval& mi : tl.measurements) {
    const JointState j = joint_state_at(tl, 0.5 * (mi.start_s + mi.end_s));
    EXPECT_NEAR(j.counter_rate_rad_s, -mi.rate_rad_s + mi.counter_rate_offset_rad_s, 1e-12);
    EXPECT_NEAR(j.main_rate_rad_s, mi.rate_rad_s, 1e-12);
  }
}

TEST(RatePlatformTimeline, TheReducersDwellsAreThePlansPositions) {
  Scenario s = rate_platform_scenario();
  s.test.revolutions = 5;  // the scatter at an offset is about a line and the heading's sweep: 4 parameters
  s.test.rates_rad_s = {9.9, 0.0};
  const Timeline tl = make_timeline(s.test, s.model());
  const Pipeline p = run(s);
  const std::vector<Position> plan = test_positions(s.test);
  ASSERT_EQ(p.reduction.positions.size(), plan.size());
  // The reducer knows nothing of the plan's timing: it measures once the encoders have been steady for the
  // settle time, and for the planned duration. Its measured part must lie in the machine's steady state
  // before the plan's measurement interval ends (the settle interval before it is steady too: a run may
  // start in the last tenths of a second of a ramp, which the settle time then drops), and be the
  // planned length (to two samples: the reducer works on the samples).
  const double tolerance_s = 2.0 / s.test.sample_rate_hz;
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const ReducedPosition& r = p.reduction.positions[i];
    EXPECT_EQ(r.index, plan[i].index);
    EXPECT_EQ(r.counter_rate_offset_rad_s, plan[i].counter_rate_offset_rad_s);
    EXPECT_EQ(r.rate_rad_s, plan[i].rate_rad_s);
    // The dwell it came from lies inside the plan's measurement interval of this position.
    const Dwell& d = p.reduction.dwells[static_cast<std::size_t>(r.dwell)];
    bool inside = false;
    for (const MeasurementInterval& mi : tl.measurements)
      if (mi.rate_rad_s == plan[i].rate_rad_s &&
          mi.counter_rate_offset_rad_s == plan[i].counter_rate_offset_rad_s &&
          mi.beta_rad == plan[i].beta_rad &&
          (mi.kind == SegmentKind::kDwell || mi.gamma_rad == plan[i].gamma_rad))
        inside |= d.first_time_s >= mi.start_s - s.test.settle_s && d.last_time_s <= mi.end_s + tolerance_s &&
                  d.last_time_s - d.first_time_s >= mi.end_s - mi.start_s - tolerance_s;
    EXPECT_TRUE(inside) << "position " << plan[i].index << " dwell " << d.first_time_s << ".."
                        << d.last_time_s << " rate " << d.planned_rate_rad_s << " offset "
                        << d.planned_counter_rate_offset_rad_s << " beta " << d.beta_rad;
    // The counter line fitted to the encoder: -rate + offset (+ the machine's delta omega).
    if (!d.is_static) {
      EXPECT_NEAR(
          d.counter.rate_rad_s,
          -plan[i].rate_rad_s + plan[i].counter_rate_offset_rad_s + s.errors.counter_rate_mismatch_rad_s,
          1e-9);
    }
  }
  EXPECT_EQ(p.reduction.warnings.size(), 1u);  // the noise-free record's "no scatter" only
}

// ----------------------------------------------------------------------------------------------------------
// Identification.

TEST(RatePlatformCalibrate, NoiseFreeRecoversScaleFactorMisalignmentsAndTheDrift) {
  const Scenario s = rate_platform_scenario();
  const Pipeline p = run(s);
  const CalibrationResult r = identify_with(s, p, GyroModel::kDriftRate);
  EXPECT_EQ(r.rank, 13);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    ASSERT_TRUE(r.coefficients[k].identifiable) << kCoefficientNames[k];
    EXPECT_NEAR(r.coefficients[k].value, s.gyro.values[k], 1e-7) << kCoefficientNames[k];
  }
  ASSERT_TRUE(r.coefficients[kNumGyroCoefficients].identifiable);
  ASSERT_TRUE(r.coefficients[kNumGyroCoefficients + 2].identifiable);
  EXPECT_NEAR(r.coefficients[kNumGyroCoefficients].value, 150.0, 1e-3);
  EXPECT_NEAR(r.coefficients[kNumGyroCoefficients + 2].value, 40.0, 1e-3);
  // dO: only the Earth rate's horizontal part reaches it; noise-free it still comes out, within far less than
  // the ~10 arcsec a noisy record leaves it.
  if (r.coefficients[kNumGyroCoefficients + 1].identifiable) {
    EXPECT_NEAR(r.coefficients[kNumGyroCoefficients + 1].value, -25.0, 0.1);
  }
  EXPECT_TRUE(has_warning(r, "input_axis_misalignment_O_arcsec"));
  // The drift model alone cannot explain the scale factor: its residuals are far beyond the scatter at the
  // offsets, and the calibration is refused rather than stated with an uncertainty (docs/calibration.md,
  // "When the residuals misfit").
  try {
    identify_with(s, p, GyroModel::kDrift);
    ADD_FAILURE() << "the drift model's misfit was not refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("inconsistent with the record's own scatter"), std::string::npos)
        << e.what();
  }
}

TEST(RatePlatformCalibrate, UncertaintiesOfScaleFactorAndMisalignmentTowardSAreHonest) {
  // Over many noisy simulations (estimate - truth) / std of e and dS has unit standard deviation: the
  // reduction's scatter between revolutions must not count the Earth rate that sweeps through a dwell at an
  // offset (docs/physics.md section 15) as noise, nor may the weights lose it.
  // A perfect machine: a machine error that turns with the main axis (a wobble, a tilted main axis) mixes
  // with the heading's sweep into terms that are neither gamma's harmonics nor the sweep, which the scatter
  // between revolutions then counts as noise (standard errors too large: docs/rate_platform.md, "Not done").
  Scenario s = rate_platform_scenario();
  s.errors = CentrifugeErrors{};
  s.noise = default_scenario().noise;  // white rate noise, 0.002 deg/rt(h)
  s.test.revolutions = 30;
  s.test.sample_rate_hz = sanitized() ? 30.0 : 50.0;
  const int trials = sanitized() ? 100 : 120;  // the spread of sd is about 1/sqrt(2 trials) = 0.07
  const std::vector<PositionModelTerms> model_terms = run(s, 1).model_terms;
  std::vector<double> z_e, z_s;
  for (int trial = 0; trial < trials; ++trial) {
    Reducer reducer(s.test, ReduceOptions{}, "simulated", 9.9);
    SimulationOptions so;
    so.seed = 5000 + static_cast<std::uint64_t>(trial);
    simulate(s, so, [&](const RecordSample& sample) { reducer.push(sample); });
    CalibrationOptions o;
    o.gyro_model = GyroModel::kDriftRate;
    const CalibrationResult r = identify(reducer.finish(), model_terms, s.model(), o);
    ASSERT_TRUE(r.coefficients[kNumGyroCoefficients].identifiable &&
                r.coefficients[kNumGyroCoefficients + 2].identifiable);
    z_e.push_back((r.coefficients[kNumGyroCoefficients].value - 150.0) /
                  r.coefficients[kNumGyroCoefficients].std);
    z_s.push_back((r.coefficients[kNumGyroCoefficients + 2].value - 40.0) /
                  r.coefficients[kNumGyroCoefficients + 2].std);
  }
  for (const auto& [name, z] : {std::make_pair("e", z_e), std::make_pair("dS", z_s)}) {
    double mean = 0, var = 0;
    for (double x : z) mean += x;
    mean /= static_cast<double>(z.size());
    for (double x : z) var += (x - mean) * (x - mean);
    const double sd = std::sqrt(var / static_cast<double>(z.size() - 1));
    EXPECT_GT(sd, 0.85) << name;
    EXPECT_LT(sd, 1.15) << name;
    EXPECT_LT(std::abs(mean), 4.0 / std::sqrt(trials)) << name;
  }
}

TEST(RatePlatformCalibrate, ARateTableAloneGivesTheScaleFactorAndTheBias) {
  // Main rate 0, offsets +-0.5 and +-1 rad/s, beta = 90/270 deg (I up and down): a plain rate table.
  Scenario s = default_scenario();
  s.noise = GyroNoise{};
  s.gyro_rate = {150.0, -25.0, 40.0};
  s.test.rates_rad_s = {0.0};
  s.test.counter_rate_offsets_rad_s = {0.5, -0.5, 1.0, -1.0};
  s.test.beta_rad = {kPi / 2, 3 * kPi / 2};
  s.test.sample_rate_hz = 20.0;
  s.test.revolutions = 3;
  s.test.settle_s = 1.0;
  const Pipeline p = run(s);
  const CalibrationResult r = identify_with(s, p, GyroModel::kDriftRate);
  ASSERT_TRUE(r.coefficients[kNumGyroCoefficients].identifiable);
  EXPECT_NEAR(r.coefficients[kNumGyroCoefficients].value, 150.0, 1e-3);
  // At 1 g with I vertical, dF and dII only appear together (a_I^2 = 1): the bias comes as dF + dII (and dSS,
  // dOO where the machine's tilts leave them unexcited), whose truth is the combination applied to the truth.
  const auto& dF = r.coefficients[static_cast<std::size_t>(Coefficient::dF)];
  if (dF.identifiable) {
    EXPECT_NEAR(dF.value, s.gyro[Coefficient::dF], 1e-6);
  } else {
    bool found = false;
    for (const NamedEstimate& c : r.combinations) {
      if (c.coefficients.empty() || c.coefficients[0] == 0.0) continue;
      double truth = 0.0;
      for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) truth += c.coefficients[k] * s.gyro.values[k];
      for (std::size_t k = 0; k < kNumRateTerms && kNumGyroCoefficients + k < c.coefficients.size(); ++k) {
        const double v[3] = {150.0, -25.0, 40.0};
        truth += c.coefficients[kNumGyroCoefficients + k] * v[k];
      }
      EXPECT_NEAR(c.value, truth, 1e-6) << c.name;
      found = true;
    }
    EXPECT_TRUE(found);
  }
  const auto& dI = r.coefficients[static_cast<std::size_t>(Coefficient::dI)];
  ASSERT_TRUE(dI.identifiable);
  EXPECT_NEAR(dI.value, s.gyro[Coefficient::dI], 1e-6);
}

TEST(RatePlatformCalibrate, WithoutOffsetsPlanSaysTheScaleFactorIsBarelyIdentifiable) {
  Scenario s = rate_platform_scenario();
  s.test.counter_rate_offsets_rad_s = {0.0};
  const Pipeline p = run(s);
  const CalibrationResult r = identify_with(s, p, GyroModel::kDriftRate);
  EXPECT_TRUE(has_warning(r, "barely identifiable"));
}

TEST(RatePlatformPlan, PlanStatesThePredictedUncertaintyOfTheScaleFactorWithAndWithoutOffsets) {
  Scenario s = rate_platform_scenario();
  s.noise = default_scenario().noise;
  CalibrationOptions o;
  o.gyro_model = GyroModel::kDriftRate;
  const CalibrationResult with = predict_calibration(s, o);
  s.test.counter_rate_offsets_rad_s = {0.0};
  const CalibrationResult without = predict_calibration(s, o);
  ASSERT_TRUE(with.coefficients[kNumGyroCoefficients].identifiable);
  // Offsets of 0.25 rad/s put 0.25 rad/s on I or S, the Earth rate at most 7e-5 rad/s: e's uncertainty
  // shrinks by orders of magnitude (more than 100 here), and plan says why it is large without them.
  EXPECT_GT(without.coefficients[kNumGyroCoefficients].std,
            100.0 * with.coefficients[kNumGyroCoefficients].std);
  EXPECT_TRUE(has_warning(without, "barely identifiable"));
  EXPECT_FALSE(has_warning(with, "barely identifiable"));
  // dO is weak either way, and said so with its uncertainty.
  EXPECT_TRUE(has_warning(with, "input_axis_misalignment_O_arcsec"));
  EXPECT_GT(with.coefficients[kNumGyroCoefficients + 1].std,
            100.0 * with.coefficients[kNumGyroCoefficients + 2].std);
}

TEST(RatePlatformCalibrate, ClosedFormUsesTheSixteenPositionsAtOffsetZeroAndSaysWhatItLeftOut) {
  Scenario s = rate_platform_scenario();
  s.gyro_rate = GyroRateErrors{};
  s.test.rates_rad_s = {9.9};
  const Pipeline p = run(s);
  const CalibrationResult cf = identify_with(s, p, GyroModel::kDrift, Method::kClosedForm);
  EXPECT_TRUE(has_warning(cf, "leaves out the other 32 positions of the plan (32 at a counter rate offset"));
  // The 16 positions at offset 0 give the closed forms exactly what a plain test gives.
  Scenario plain = s;
  plain.test.counter_rate_offsets_rad_s = {0.0};
  const CalibrationResult ref = identify_with(plain, run(plain), GyroModel::kDrift, Method::kClosedForm);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    EXPECT_EQ(cf.coefficients[k].identifiable, ref.coefficients[k].identifiable);
    if (ref.coefficients[k].identifiable) {
      EXPECT_NEAR(cf.coefficients[k].value, ref.coefficients[k].value, 1e-9) << kCoefficientNames[k];
    }
  }
  EXPECT_THROW(identify_with(s, p, GyroModel::kDriftRate, Method::kClosedForm), Error);
}

TEST(RatePlatformConfig, KeysReadAndWriteBack) {
  const Scenario s = parse_scenario(
      "[gyro]\nscale_factor_error_ppm = 150.0\ninput_axis_misalignment_arcsec = [-25.0, 40.0]\n"
      "[test]\ncounter_rate_offsets_rad_s = [0.0, 0.25, -0.25]\n[calibration]\ngyro_model = \"drift+rate\"\n",
      "t.toml");
  EXPECT_EQ(s.gyro_rate.scale_factor_error_ppm, 150.0);
  EXPECT_EQ(s.gyro_rate.input_axis_misalignment_O_arcsec, -25.0);
  EXPECT_EQ(s.gyro_rate.input_axis_misalignment_S_arcsec, 40.0);
  EXPECT_EQ(s.test.counter_rate_offsets_rad_s, (std::vector<double>{0.0, 0.25, -0.25}));
  EXPECT_EQ(s.gyro_model, GyroModel::kDriftRate);
  const Scenario back = parse_scenario(scenario_to_toml(s), "back.toml");
  EXPECT_EQ(back.gyro_rate.input_axis_misalignment_S_arcsec, 40.0);
  EXPECT_EQ(back.test.counter_rate_offsets_rad_s, s.test.counter_rate_offsets_rad_s);
  EXPECT_EQ(back.gyro_model, GyroModel::kDriftRate);
  EXPECT_THROW(parse_scenario("[calibration]\ngyro_model = \"rate\"\n", "t.toml"), Error);
  EXPECT_THROW(parse_scenario("[gyro]\ninput_axis_misalignment_arcsec = [1.0]\n", "t.toml"), Error);
}

}  // namespace
}  // namespace gyrocal
