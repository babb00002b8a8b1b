// The rate the model terms follow (reduce/measured_rate.hpp, identify/model_terms.hpp; docs/calibration.md,
// "The rate the channels follow"): the spline of the main encoder against independent truths (a rate given in
// closed form, the rig generator's own joint states), and what a constant-rate line misses instead.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/model_terms.hpp"
#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/reduce/measured_rate.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "support/rig_record.hpp"

namespace gyrocal {
namespace {

/// An arm at w (1 + eps sin(wr t)) from angle a0, read by an encoder quantised to q (rad; 0: exact), sampled
/// at fs for T s, fitted; the truth's rate at each sample beside the fit's.
struct Synthetic {
  MeasuredMotion motion;
  std::vector<double> x, rate_truth;
};
Synthetic synthetic(double w, double eps, double wr, double q, double fs, double duration, double a0) {
  Synthetic s;
  const double dt = 1.0 / fs;
  MeasuredMotionFit fit(dt, 0.0, a0, w, 2.0 * kPi / w, duration);
  fit.begin_phase(0.0);
  const auto n = static_cast<std::size_t>(duration * fs);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * dt;
    double a = a0 + w * t + w * eps * (1.0 - std::cos(wr * t)) / wr;
    if (q > 0) a = q * std::round(a / q);
    fit.add(t, a);
    s.x.push_back(t);
    s.rate_truth.push_back(w * (1.0 + eps * std::sin(wr * t)));
  }
  s.motion = fit.finish();
  return s;
}

TEST(MeasuredRate, TheSplineFollowsARippleWithinItsStatedNoiseAndAConstantRateMissesItsAmplitude) {
  // 12 g at 1 m (w = 10.85 rad/s), ripple 5e-5 at 0.37 Hz, 200 Hz, encoders of 2^16 counts a turn.
  const double w = std::sqrt(12.0 * kStandardGravityMS2), eps = 5e-5, wr = 2.0 * kPi * 0.37;
  const double q = 2.0 * kPi / 65536.0;
  const Synthetic s = synthetic(w, eps, wr, q, 200.0, 30.0, 0.3);
  const MeasuredMotion& m = s.motion;
  EXPECT_TRUE(m.resolved) << m.chi2 << " dof " << m.dof;
  EXPECT_TRUE(m.quanta_resolved);
  // The readings' scatter is the quantum's: q / sqrt(12) within 10 %.
  EXPECT_NEAR(m.residual_rad, q / std::sqrt(12.0), 0.1 * q / std::sqrt(12.0));
  // Away from the ends (one knot interval), the rate is the truth's within 5 of its stated standard errors;
  // its RMS error is the stated noise within a factor 2 (the noise statement is honest).
  double worst = 0.0, sum2 = 0.0, line_worst = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (s.x[i] < m.knot_interval_s || s.x[i] > s.x.back() - m.knot_interval_s) continue;
    const double e = m.at(0, s.x[i]).rate_rad_s - s.rate_truth[i];
    worst = std::max(worst, std::abs(e));
    sum2 += e * e;
    ++n;
    line_worst = std::max(line_worst, std::abs(w + m.phases[0].line_rate_rad_s - s.rate_truth[i]));
  }
  const double rms = std::sqrt(sum2 / n);
  EXPECT_LT(worst, 5.0 * m.rate_noise_rad_s) << worst << " vs noise " << m.rate_noise_rad_s;
  EXPECT_GT(rms, 0.3 * m.rate_noise_rad_s);
  EXPECT_LT(rms, 2.0 * m.rate_noise_rad_s);
  // The constant rate misses by the ripple's amplitude; the spline is 10x closer.
  EXPECT_GT(line_worst, 0.9 * eps * w);
  EXPECT_LT(worst, 0.1 * eps * w);
  EXPECT_NEAR(m.max_rate_deviation_rad_s, eps * w, 0.1 * eps * w);
}

TEST(MeasuredRate, WithoutARippleTheFTestFindsNoneAndAStaircaseIsNotTakenForARate) {
  // Quantisation at many rates and phases: never followed (at some rates the rounding error is a slow
  // sawtooth that the F-test alone resolves; the count criterion refuses it).
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> phase(0.0, 1.0), rate(5.0, 12.0);
  for (int k = 0; k < 20; ++k) {
    const Synthetic s = synthetic(rate(rng), 0.0, 1.0, 0.1 * kDegToRad, 200.0, 20.0, 2.0 * kPi * phase(rng));
    EXPECT_FALSE(s.motion.resolved && s.motion.quanta_resolved)
        << k << ": " << s.motion.chi2 << " dof " << s.motion.dof << ", deviation "
        << s.motion.max_angle_deviation_rad << " count bound " << s.motion.count_bound_rad;
  }
  // 0.01 rad/s read by 0.1 deg counts: a count every 0.17 s, the knot interval crosses 1.4 counts.
  const Synthetic slow = synthetic(0.01, 0.0, 1.0, 0.1 * kDegToRad, 200.0, 60.0, 0.1);
  EXPECT_FALSE(slow.motion.quanta_resolved);
}

// ---- The model terms on a rig's record (tests/support/rig_record.hpp: the exact model at the generator's
// own joint states)
// --------------------------------------------------------------------------------------------

Scenario rig_scenario(double sample_rate_hz) {
  Scenario s = default_scenario();
  s.test.sample_rate_hz = sample_rate_hz;
  s.test.revolutions = 8;
  s.test.rates_rad_s = {9.9, 7.0};
  return s;
}

struct RigReduction {
  std::vector<testing::RigRow> rows;
  Reduction reduction;
};

RigReduction reduce_rig(const Scenario& s, const testing::RigImperfections& imp, std::uint64_t seed) {
  RigReduction r;
  testing::rig_rows(s, imp, testing::RigMotion{}, seed,
                    [&](const testing::RigRow& x) { r.rows.push_back(x); });
  Reducer reducer(s.test, ReduceOptions{}, "rig.csv", s.centrifuge.rate_rad_s);
  for (const RecordSample& x : testing::as_samples(r.rows)) reducer.push(x);
  r.reduction = reducer.finish();
  return r;
}

/// The specific force (g, gyro axes) at joint state j with beta as planned.
Eigen::Vector3d force(const CentrifugeModel& model, JointState j, double beta) {
  j.position_angle_rad = beta;
  return exact_inputs(model, j).specific_force_g;
}

/// Per position: the true specific force (a_I, a_O, a_S), reduced by the output's operator on the dwell's
/// samples, the truth taken from the generator's row at each sample's instant (no jitter: the stamps are the
/// instants).
std::vector<Eigen::Vector3d> true_reduced_force(const Scenario& s, const RigReduction& r) {
  const CentrifugeModel model = s.model();
  const double fs = s.test.sample_rate_hz;
  std::vector<std::vector<DwellValues>> per_dwell;
  for (const Dwell& d : r.reduction.dwells) {
    DwellAccumulator acc(ReduceOptions{}, d.gammas_rad, d.is_static, 3, d.planned_duration_s, false, 0.0);
    // The output's operator: its basis angle as the reducer took it (Dwell::basis_angle).
    BasisAngleCursor basis(d.basis_angle);
    std::size_t sample = 0;
    for (const TimeStretch& st : d.stretches)
      for (std::size_t i = 0; i < st.count; ++i, ++sample) {
        const double dt = static_cast<double>(i) * st.interval_s, t = st.first_time_s + dt;
        // The row of that instant (rows are at k / fs; a gap leaves some out).
        const auto k = static_cast<long>(std::llround(t * fs));
        const auto it =
            std::lower_bound(r.rows.begin(), r.rows.end(), static_cast<double>(k) / fs - 0.25 / fs,
                             [](const testing::RigRow& a, double v) { return a.time_s < v; });
        EXPECT_NEAR(it->time_s, t, 1e-6);
        const Eigen::Vector3d f = force(model, it->truth, d.beta_rad);
        const double v[3] = {f.x(), f.y(), f.z()};
        acc.add(t, -basis.at(sample, t), v);
      }
    std::vector<DwellValues> cols;
    for (int c = 0; c < 3; ++c) cols.push_back(acc.finish(c));
    per_dwell.push_back(cols);
  }
  std::vector<Eigen::Vector3d> out;
  for (const ReducedPosition& p : r.reduction.positions) {
    const auto& cols = per_dwell[static_cast<std::size_t>(p.dwell)];
    const auto slot = static_cast<std::size_t>(p.gamma_slot);
    out.emplace_back(cols[0].value[slot], cols[1].value[slot], cols[2].value[slot]);
  }
  return out;
}

/// The largest |model term - truth| of a_I, a_O, a_S over the positions, g.
double worst_force_miss(const std::vector<PositionModelTerms>& ch,
                        const std::vector<Eigen::Vector3d>& truth) {
  double worst = 0.0;
  for (std::size_t p = 0; p < ch.size(); ++p)
    for (int c = 0; c < 3; ++c)
      worst =
          std::max(worst, std::abs(ch[p].regressors_exact[static_cast<std::size_t>(1 + c)] - truth[p][c]));
  return worst;
}

/// The largest miss of the model terms' specific force against the truth's at the samples, on the measured
/// joints and on the lines; and the largest miss of the main rate.
struct SampleMiss {
  double followed = 0.0, line = 0.0, rate = 0.0;
};
SampleMiss sample_miss(const Scenario& s, const RigReduction& r) {
  const CentrifugeModel model = s.model();
  SampleMiss out;
  for (const Dwell& d : r.reduction.dwells)
    for (std::size_t si = 0; si < d.stretches.size(); ++si) {
      const TimeStretch& st = d.stretches[si];
      for (std::size_t i = 0; i < st.count; ++i) {
        const double dt = static_cast<double>(i) * st.interval_s, t = st.first_time_s + dt;
        const auto it = std::lower_bound(r.rows.begin(), r.rows.end(), t - 1e-6,
                                         [](const testing::RigRow& a, double v) { return a.time_s < v; });
        EXPECT_NEAR(it->time_s, t, 1e-6);
        const JointState j = measured_joints(d, si, i);
        out.rate = std::max(out.rate, std::abs(j.main_rate_rad_s - it->truth.main_rate_rad_s));
        JointState line;
        line.main_angle_rad = st.main_at_first_rad + d.main.rate_rad_s * dt;
        line.main_rate_rad_s = d.main.rate_rad_s;
        line.counter_angle_rad = st.counter_at_first_rad + d.counter.rate_rad_s * dt;
        line.counter_rate_rad_s = d.counter.rate_rad_s;
        const Eigen::Vector3d truth = force(model, it->truth, d.beta_rad);
        out.followed = std::max(out.followed, (force(model, j, d.beta_rad) - truth).cwiseAbs().maxCoeff());
        out.line = std::max(out.line, (force(model, line, d.beta_rad) - truth).cwiseAbs().maxCoeff());
      }
    }
  return out;
}

/// The largest miss of the reduced model terms' specific force against the truth's, following the measured
/// motion and on the lines.
std::pair<double, double> reduced_miss(const Scenario& s, const RigReduction& r) {
  const CentrifugeModel model = s.model();
  const std::vector<Eigen::Vector3d> truth = true_reduced_force(s, r);
  std::vector<DwellModelTermsRoute> routes;
  const std::vector<PositionModelTerms> followed =
      reduce_model_terms(r.reduction, model, ReduceOptions{}, 0, ModelTermsRoute::kExact, &routes);
  for (const DwellModelTermsRoute& x : routes) EXPECT_TRUE(x.measured_rate);
  Reduction lines = r.reduction;
  for (Dwell& d : lines.dwells) d.measured = MeasuredMotion{};
  const std::vector<PositionModelTerms> on_lines = reduce_model_terms(lines, model, ReduceOptions{});
  return {worst_force_miss(followed, truth), worst_force_miss(on_lines, truth)};
}

TEST(MeasuredRate, OnARippledRigRecordTheChannelsSpecificForceIsTheTruthsWhereTheLineMissesIt) {
  // 200 Hz, 9.9 and 7 rad/s at 1 m (10 g and 5 g), a drive ripple of 2e-4 at 0.37 Hz, 8-revolution dwells.
  const Scenario s = rig_scenario(200.0);
  const CentrifugeModel model = s.model();
  testing::RigImperfections imp;
  imp.ripple = 2e-4;
  const RigReduction r = reduce_rig(s, imp, 3);
  ASSERT_EQ(r.reduction.dwells.size(), 8u);
  for (const Dwell& d : r.reduction.dwells) {
    EXPECT_TRUE(d.measured.resolved && d.measured.quanta_resolved);
    EXPECT_GT(measured_rate_effect_g(model, d), kMeasuredRateFloorG);
  }
  // At the samples the line misses by the ripple's order (2 eps A = 4 mg in magnitude, A eps w / wr = 8.5 mg
  // in direction); the measured motion by 1 % of that (the spline's approximation, largest at the dwells'
  // ends).
  const SampleMiss m = sample_miss(s, r);
  EXPECT_GT(m.line, 5e-3);
  EXPECT_LT(m.followed, 0.01 * m.line);
  EXPECT_LT(m.rate, 0.02 * imp.ripple * 7.0);
  // Reduced by the operator: 4e-6 g against the line's 2e-4 g (the ripple's leakage into the fit's values).
  const auto [followed, line] = reduced_miss(s, r);
  EXPECT_LT(followed, 1e-5);
  EXPECT_GT(line, 1.5e-4);
}

TEST(MeasuredRate, WithEncodersOf2To16CountsTheMeasuredMotionStillHalvesWhatTheLineMisses) {
  // The spline's own noise (readings rounded to 2^16 counts a turn, 200 Hz, dwells of 5 and 7 s): the
  // reduced miss is limited by it, 4e-5 g here against the line's 2e-4 g.
  const Scenario s = rig_scenario(200.0);
  testing::RigImperfections imp;
  imp.ripple = 2e-4;
  imp.angle_quantum_deg = 360.0 / 65536.0;
  const RigReduction r = reduce_rig(s, imp, 3);
  const auto [followed, line] = reduced_miss(s, r);
  EXPECT_LT(followed, 0.5 * line);
  EXPECT_GT(line, 1.5e-4);
}

TEST(MeasuredRate, ACalibrationOnARippledRecordRecoversTheTruthWithTheSameUncertainties) {
  // The gyro on the same record with and without a ripple of 2e-4 (same noise): every coefficient within 4 of
  // its std of the truth, and the std not inflated by the ripple (within 2 %).
  const Scenario s = rig_scenario(50.0);
  const auto calibrate = [&](double ripple) {
    testing::RigImperfections imp;
    imp.ripple = ripple;
    imp.angle_quantum_deg = 0.1;
    const RigReduction r = reduce_rig(s, imp, 21);
    CalibrationOptions o;
    o.method = Method::kLeastSquares;
    return identify(r.reduction, reduce_model_terms(r.reduction, s.model(), ReduceOptions{}), s.model(), o);
  };
  const CalibrationResult smooth = calibrate(0.0), rippled = calibrate(2e-4);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    const CoefficientEstimate& e = rippled.coefficients[k];
    ASSERT_TRUE(e.identifiable) << kCoefficientNames[k];
    EXPECT_NEAR(e.value, s.gyro.values[k], 4.0 * e.std) << kCoefficientNames[k];
    EXPECT_NEAR(e.std, smooth.coefficients[k].std, 0.02 * smooth.coefficients[k].std) << kCoefficientNames[k];
  }
}

TEST(MeasuredRate, WithoutARippleTheChannelsTakeTheLineAsBefore) {
  // Quantised encoders, jitter, no ripple: the F-test finds none and every model term is the line route's,
  // bit for bit.
  const Scenario s = rig_scenario(50.0);
  testing::RigImperfections imp;
  imp.angle_quantum_deg = 0.1;
  imp.jitter_s = 1e-4;
  imp.rate_offset = 1e-3;
  const RigReduction r = reduce_rig(s, imp, 4);
  std::vector<DwellModelTermsRoute> routes;
  const std::vector<PositionModelTerms> ch =
      reduce_model_terms(r.reduction, s.model(), ReduceOptions{}, 0, ModelTermsRoute::kExact, &routes);
  Reduction lines = r.reduction;
  for (Dwell& d : lines.dwells) {
    EXPECT_FALSE(d.measured.resolved && d.measured.quanta_resolved)
        << d.measured.chi2 << " dof " << d.measured.dof;
    d.measured = MeasuredMotion{};
  }
  for (const DwellModelTermsRoute& x : routes) EXPECT_FALSE(x.measured_rate);
  const std::vector<PositionModelTerms> ref = reduce_model_terms(lines, s.model(), ReduceOptions{});
  for (std::size_t p = 0; p < ch.size(); ++p) {
    EXPECT_EQ(ch[p].omega_exact_deg_h, ref[p].omega_exact_deg_h);
    EXPECT_EQ(ch[p].regressors_exact, ref[p].regressors_exact);
  }
}

}  // namespace
}  // namespace gyrocal
