// A guard on exactness (issue 26, item 6): the record's output and the model terms are reduced by one
// and the same operator (reduce/dwell_accumulator.hpp on the record's side; identify/model_terms.hpp on the
// model's: the same samples, the same times, the same basis angle, the same outliers left out). A record
// whose output is exactly the gyro's output equation at the joints the model terms take then reduces to
// exactly the model's reduced model terms times the coefficients, position by position, to rounding; a column
// added in the wrong place, a sample left out of one and not the other, a time shifted by a sample breaks
// that equality.
//
// The record comes from the rig generator (tests/support/rig_record.hpp: its own timeline and the exact model
// at its own joint states, independent of the simulator and of the reducer), noise-free, with what makes the
// bookkeeping hard: a gap, the settle time, a drive turning off its planned rate, ramps between dwells, and,
// where the model terms follow the measured motion, a drive's ripple and spikes (rows the output's outlier
// rule leaves out; on the dwell's lines the model terms take every sample, outliers included, by design:
// docs/ calibration.md, "Rejected samples are left out"). A counter platform's wobble at its 6th harmonic
// puts ~100 deg/h into the output at harmonics 5 and 7 of gamma, outside the dwell fit's harmonics 0 to 3: a
// sample taken by one reduction and not the other moves its values far above rounding. The expected values
// are the gyro's output equation (model/gyro.hpp) applied to the model's reduced model terms with the
// scenario's coefficients, or an accelerometer's design row (sensor/accelerometer.hpp) with its truth's
// products; the data's are the reducer's.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/model_terms.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/model/gyro.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "support/rig_record.hpp"

namespace gyrocal {
namespace {

/// The default scenario at two rates, 8 revolutions per dwell at 100 Hz, with a wobble of the counter
/// platform at its 6th harmonic (2 arcsec): content of the output beyond the fit's harmonics.
Scenario exactness_scenario() {
  Scenario s = default_scenario();
  s.test.sample_rate_hz = 100.0;
  s.test.revolutions = 8;
  s.test.rates_rad_s = {9.9, 7.0};
  s.errors.counter_wobble_x_rad.terms.push_back({6, 1e-5, 0.3});
  return s;
}

/// A noise-free rig record: a gap in the third dwell, a drive 1e-3 off its planned rate; with `ripple` > 0
/// a ripple of its rate, which the model terms follow through the measured motion, and six spikes.
testing::RigImperfections imperfections(double ripple) {
  testing::RigImperfections imp;
  imp.gap_fraction = 0.1;
  imp.rate_offset = 1e-3;
  imp.ripple = ripple;
  imp.spikes = ripple > 0.0 ? 6 : 0;
  return imp;
}

std::vector<testing::RigRow> rig(const Scenario& s, const testing::RigImperfections& imp) {
  testing::RigMotion motion;
  motion.noise_deg_h = 0.0;
  std::vector<testing::RigRow> rows;
  testing::rig_rows(s, imp, motion, 7, [&](const testing::RigRow& x) { rows.push_back(x); });
  return rows;
}

/// The rows reduced as calibrate reduces them for the scenario's sensor (reduction_plan: an accelerometer's
/// spinning dwells at seven gamma, their whole harmonic content).
Reduction reduce_rows(const Scenario& s, const std::vector<testing::RigRow>& rows) {
  Reducer reducer(reduction_plan(s.test, s.sensor_kind, ReduceOptions{}), ReduceOptions{}, "rig.csv",
                  s.centrifuge.rate_rad_s);
  for (const RecordSample& x : testing::as_samples(rows)) reducer.push(x);
  return reducer.finish();
}

/// The gyro's output equation on a position's reduced model terms: omega_I + sum_k c_k x_k, deg/h
/// (model/gyro.hpp, docs/physics.md section 4; the model terms are linear functionals of the samples, so the
/// equation commutes with the reduction).
double model_output_deg_h(const Scenario& s, const PositionModelTerms& ch) {
  double y = ch.omega_exact_deg_h;
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) y += s.gyro.values[k] * ch.regressors_exact[k];
  return y;
}

/// The largest |data - model| over the positions, deg/h, and the largest |data|.
struct Mismatch {
  double worst = 0.0, scale = 0.0;
};
Mismatch mismatch(const Scenario& s, const Reduction& r, ModelTermsRoute route) {
  const std::vector<PositionModelTerms> ch = reduce_model_terms(r, s.model(), ReduceOptions{}, 0, route);
  Mismatch m;
  for (std::size_t i = 0; i < r.positions.size(); ++i) {
    const double data = r.positions[i].mean, model = model_output_deg_h(s, ch[i]);
    m.worst = std::max(m.worst, std::abs(data - model));
    m.scale = std::max(m.scale, std::abs(data));
  }
  return m;
}

/// The index of a row in the measured part of a dwell that the outlier rule kept: the middle of the first
/// spinning dwell's first stretch.
std::size_t a_measured_row(const Reduction& r, const std::vector<testing::RigRow>& rows) {
  for (const Dwell& d : r.dwells) {
    if (d.is_static || d.stretches.empty()) continue;
    const TimeStretch& st = d.stretches.front();
    const double t = st.first_time_s + static_cast<double>(st.count / 2) * st.interval_s;
    const auto it = std::lower_bound(rows.begin(), rows.end(), t - 1e-6,
                                     [](const testing::RigRow& a, double v) { return a.time_s < v; });
    EXPECT_NEAR(it->time_s, t, 1e-6);
    return static_cast<std::size_t>(it - rows.begin());
  }
  ADD_FAILURE() << "no spinning dwell";
  return 0;
}

TEST(ReductionExactness, OnTheDwellsLinesTheDataAndTheModelAreReducedByOneOperator) {
  const Scenario s = exactness_scenario();
  std::vector<testing::RigRow> rows = rig(s, imperfections(0.0));
  const Reduction r = reduce_rows(s, rows);
  ASSERT_EQ(r.positions.size(), 32u);
  // What the bookkeeping must agree on: a gap, the settle time dropped, a rate off the plan.
  EXPECT_GE(r.gaps, 1u);
  for (const Dwell& d : r.dwells) {
    EXPECT_GT(d.quality.settle_rows, 0u);
    EXPECT_FALSE(d.measured.resolved && d.measured.quanta_resolved);  // the lines, no ripple
  }
  // Every sample evaluated, and the Fourier series summed in closed form (the default): the same to rounding.
  const Mismatch every = mismatch(s, r, ModelTermsRoute::kEverySample);
  const Mismatch fourier = mismatch(s, r, ModelTermsRoute::kExact);
  EXPECT_GT(every.scale, 10.0);
  EXPECT_LT(every.worst, 1e-9) << "largest reduced output " << every.scale << " deg/h";
  EXPECT_LT(fourier.worst, 1e-9) << "largest reduced output " << fourier.scale << " deg/h";

  // One sample of the record moved by 1 deg/h, the model left as it is: the guard sees it (the fit spreads
  // it over its dwell's positions at ~1/samples, ~1e-3 deg/h).
  rows[a_measured_row(r, rows)].output += 1.0;
  const Mismatch moved = mismatch(s, reduce_rows(s, rows), ModelTermsRoute::kEverySample);
  EXPECT_GT(moved.worst, 1e-5);
}

TEST(ReductionExactness, WhereTheChannelsFollowTheMeasuredMotionTheDataAndTheModelAreReducedByOneOperator) {
  // A drive's ripple (2e-4 at 0.37 Hz): the model terms follow the main axis' measured motion (its spline,
  // the counter platform turning back what the arm departs from its line) and the output's basis angle as the
  // reducer took it. The rig's output is the gyro at its true joints, which the spline approximates only;
  // so the record is written twice: the rows as the rig gives them, reduced; then each measured sample's
  // output replaced by the gyro's output equation at the joints the model terms take for it (measured_joints,
  // the spikes kept on their rows), and reduced again. The encoders are the same rows: the second reduction
  // finds the same dwells, lines, splines and outliers.
  const Scenario s = exactness_scenario();
  const CentrifugeModel model = s.model();
  std::vector<testing::RigRow> rows = rig(s, imperfections(2e-4));
  const Reduction first = reduce_rows(s, rows);
  ASSERT_EQ(first.positions.size(), 32u);
  std::size_t replaced = 0;
  for (const Dwell& d : first.dwells) {
    ASSERT_TRUE(d.measured.resolved && d.measured.quanta_resolved);
    // The stretches are on the dwell's clock (a gap counts as one interval there): each stretch's rows are
    // consecutive rows of the record, the first after the previous stretch's last.
    std::size_t row = 0;
    for (std::size_t si = 0; si < d.stretches.size(); ++si) {
      const TimeStretch& st = d.stretches[si];
      if (si == 0) {
        const auto it = std::lower_bound(rows.begin(), rows.end(), st.first_time_s - 1e-6,
                                         [](const testing::RigRow& a, double v) { return a.time_s < v; });
        ASSERT_NEAR(it->time_s, st.first_time_s, 1e-6);
        row = static_cast<std::size_t>(it - rows.begin());
      }
      const double record_first_s = rows[row].time_s;
      for (std::size_t i = 0; i < st.count; ++i, ++row) {
        testing::RigRow& x = rows[row];
        ASSERT_NEAR(x.time_s, record_first_s + static_cast<double>(i) * st.interval_s, 1e-6);
        // The rig's spike on this row, if any: its output minus the gyro at its true joints.
        const SensorInputs truth = exact_inputs(model, x.truth);
        const double spike =
            x.output - gyro_output_deg_h(s.gyro, truth.rate_rad_s.x(), truth.specific_force_g);
        const SensorInputs in = exact_inputs(model, measured_joints(d, si, i));
        x.output = gyro_output_deg_h(s.gyro, in.rate_rad_s.x(), in.specific_force_g) +
                   (std::abs(spike) > 1e3 ? spike : 0.0);
        ++replaced;
      }
    }
  }
  EXPECT_GT(replaced, 4000u);  // 8 dwells of 8 revolutions at 100 Hz, less the settle times
  const Reduction r = reduce_rows(s, rows);
  ASSERT_EQ(r.positions.size(), first.positions.size());
  EXPECT_EQ(r.outliers, first.outliers);
  EXPECT_GE(r.outliers, 3u);
  EXPECT_GE(r.gaps, 1u);
  const Mismatch m = mismatch(s, r, ModelTermsRoute::kExact);
  EXPECT_GT(m.scale, 10.0);
  EXPECT_LT(m.worst, 1e-9) << "largest reduced output " << m.scale << " deg/h";

  rows[a_measured_row(r, rows)].output += 1.0;
  const Mismatch moved = mismatch(s, reduce_rows(s, rows), ModelTermsRoute::kExact);
  EXPECT_GT(moved.worst, 1e-5);
}

TEST(ReductionExactness, AnAccelerometersDesignRowsAreReducedByTheOutputsOperator) {
  // The same for an accelerometer (identify/sensor_model_terms.hpp): the default accelerometer's truth,
  // noise-free, at 6 and 12 rad/s, its spinning dwells reduced to seven gamma; a ripple, spikes and a gap;
  // each measured sample's output rewritten as the accelerometer's output at the joints the model terms take.
  // The model: the design row's known part plus its regressors times the truth's products
  // (sensor/accelerometer.hpp).
  Scenario s = exactness_scenario();
  s.sensor_kind = SensorKind::kAccelerometer;
  s.accelerometer = Accelerometer{};
  s.accelerometer.noise = AccelerometerNoise{};
  s.test.rates_rad_s = {6.0, 12.0};
  s.centrifuge.rate_rad_s = 6.0;
  const CentrifugeModel model = s.model();
  std::vector<testing::RigRow> rows = rig(s, imperfections(2e-4));
  const Reduction first = reduce_rows(s, rows);
  ASSERT_EQ(first.positions.size(), 56u);  // 2 rates x 4 beta x 7 gamma
  const double k1 = s.accelerometer.coefficients[AccelCoefficient::K1];
  std::size_t replaced = 0;
  for (const Dwell& d : first.dwells) {
    ASSERT_TRUE(d.measured.resolved && d.measured.quanta_resolved);
    std::size_t row = 0;
    for (std::size_t si = 0; si < d.stretches.size(); ++si) {
      const TimeStretch& st = d.stretches[si];
      if (si == 0) {
        const auto it = std::lower_bound(rows.begin(), rows.end(), st.first_time_s - 1e-6,
                                         [](const testing::RigRow& a, double v) { return a.time_s < v; });
        ASSERT_NEAR(it->time_s, st.first_time_s, 1e-6);
        row = static_cast<std::size_t>(it - rows.begin());
      }
      const double record_first_s = rows[row].time_s;
      for (std::size_t i = 0; i < st.count; ++i, ++row) {
        testing::RigRow& x = rows[row];
        ASSERT_NEAR(x.time_s, record_first_s + static_cast<double>(i) * st.interval_s, 1e-6);
        const double spike = x.output - s.accelerometer.output(exact_inputs(model, x.truth));
        x.output = s.accelerometer.output(exact_inputs(model, measured_joints(d, si, i))) +
                   (std::abs(spike) > 0.1 * k1 ? spike : 0.0);
        ++replaced;
      }
    }
  }
  EXPECT_GT(replaced, 5000u);
  const Reduction r = reduce_rows(s, rows);
  ASSERT_EQ(r.positions.size(), first.positions.size());
  EXPECT_EQ(r.outliers, first.outliers);
  EXPECT_GE(r.outliers, 3u);
  EXPECT_GE(r.gaps, 1u);
  const Eigen::VectorXd u = s.accelerometer.products();
  const auto worst = [&](const Reduction& x) {
    const std::vector<PositionModelTerms> ch =
        reduce_sensor_model_terms(x, model, ReduceOptions{}, lone_channel(Accelerometer{}));
    double w = 0.0;
    for (std::size_t i = 0; i < x.positions.size(); ++i) {
      const DesignRow& row = ch[i].sensor_exact;
      double y = row.known;
      for (std::size_t j = 0; j < row.size; ++j) y += u[static_cast<Eigen::Index>(j)] * row.regressors[j];
      w = std::max(w, std::abs(x.positions[i].mean - y));
    }
    return w;
  };
  EXPECT_LT(worst(r), 1e-12 * 12.0 * k1);

  rows[a_measured_row(r, rows)].output += 1e-3 * k1;
  EXPECT_GT(worst(reduce_rows(s, rows)), 1e-9 * k1);
}

}  // namespace
}  // namespace gyrocal
