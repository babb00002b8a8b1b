// Increments (docs/records.md, "Increments"): an output column of increments holds the integral of the
// sensor's output over the interval that ends at each stamp. The reader divides it by its interval (the mean
// over it), the model's side of each position is the design row's mean over the same intervals, so that one
// operator reduces data and model; an increment whose interval is unknown (after a gap or a lost row, the
// first row) is left out and counted; the simulator integrates over each interval. The records here come
// from the test's own generator: composite Simpson quadrature of the exact output (not the library's rule).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/dwell_model_route.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/plan/timeline.hpp"
#include "gyrocal/record/increments.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace gyrocal {
namespace {

constexpr double kStandardGravity = 9.80665;

TEST(Increments, TheIntervalRuleIsExactForPolynomialsAndHarmonics) {
  // n nodes: the mean of s^p over [t - dt, t] exactly for p < 2n; here t = 1, dt = 1: 1 / (p + 1).
  for (int n = 1; n <= kMaxIntervalNodes; ++n) {
    const IntervalRule rule = interval_rule(n);
    ASSERT_EQ(rule.back.size(), static_cast<std::size_t>(n));
    for (int p = 0; p < 2 * n; ++p) {
      double mean = 0.0;
      for (int k = 0; k < n; ++k)
        mean += rule.weight[static_cast<std::size_t>(k)] *
                std::pow(1.0 - rule.back[static_cast<std::size_t>(k)], p);
      EXPECT_NEAR(mean, 1.0 / (p + 1.0), 1e-14) << n << " nodes, degree " << p;
    }
  }
  // The mean of e^{j f s} over [t - dt, t] over its value at t: (1 - e^{-j f dt}) / (j f dt), by hand.
  for (double phase : {0.03, 0.5, 2.0, 6.0}) {
    const std::complex<double> j(0.0, 1.0);
    const std::complex<double> expected = (1.0 - std::exp(-j * phase)) / (j * phase);
    const std::complex<double> factor = interval_mean_factor(phase / 0.005, 0.005);
    EXPECT_LT(std::abs(factor - expected), 1e-15 * std::max(1.0, 1.0 / phase)) << phase;
    // interval_nodes' rule for that phase gives it within 1e-13.
    const IntervalRule rule = interval_rule(interval_nodes(phase));
    std::complex<double> sum = 0.0;
    for (std::size_t k = 0; k < rule.back.size(); ++k)
      sum += rule.weight[k] * std::exp(-j * phase * rule.back[k]);
    EXPECT_LT(std::abs(sum - expected), 1e-13) << phase;
  }
  // A phase of 1e-6: the series 1 - j phase / 2 - phase^2 / 6 (the quotient above would cancel).
  const std::complex<double> small = interval_mean_factor(1e-6 / 0.005, 0.005);
  EXPECT_LT(std::abs(small - std::complex<double>(1.0 - 1e-12 / 6.0, -0.5e-6)), 1e-17);
  EXPECT_EQ(interval_nodes(0.0), 1);
  EXPECT_THROW(interval_rule(0), Error);
  EXPECT_THROW(interval_rule(kMaxIntervalNodes + 1), Error);
}

TEST(Increments, TheReaderDividesAnIncrementByItsIntervalAndLeavesTheFirstRowWithout) {
  RecordLayout l;
  l.outputs = {
      OutputColumn{"dv", OutputQuantity::kSpecificForce, OutputForm::kIncrement, 9.80665, 0.5, "m/s"},
      OutputColumn{"w", OutputQuantity::kRate, OutputForm::kRate, 2.0, 0.0, ""}};
  std::string error;
  ASSERT_TRUE(l.IsValid(&error)) << error;
  const std::string text =
      "time_s,main_angle_deg,counter_angle_deg,position_angle_deg,dv,w\n"
      "1.0,0,0,0,7,4\n"
      "1.25,0,0,0,1.72583125,4\n"  // 0.25 s: (1.72583125 - 0.5) / 9.80665 / 0.25 = 0.5 g
      "2.25,0,0,0,-9.30665,6\n";   // 1 s: -1 g
  RecordReader reader = RecordReader::from_string(text, l, "inc.csv");
  RecordSample s;
  ASSERT_TRUE(reader.next(s));
  EXPECT_TRUE(std::isnan(s.outputs[0]));  // no interval
  EXPECT_EQ(s.outputs[1], 2.0);           // a rate column as it always was
  ASSERT_TRUE(reader.next(s));
  EXPECT_NEAR(s.outputs[0], 0.5, 1e-15);
  ASSERT_TRUE(reader.next(s));
  EXPECT_NEAR(s.outputs[0], -1.0, 1e-15);
  EXPECT_EQ(s.outputs[1], 3.0);
}

/// An accelerometer written as velocity increments (m/s per sample) on an arm spinning at 12 rad/s, sampled
/// at 200 Hz, with machine errors: the increment's lag matters there (docs/records.md, "Increments").
Scenario increment_scenario(OutputForm form) {
  Scenario s = default_accelerometer_scenario();
  s.test.sample_rate_hz = 200.0;
  s.test.rates_rad_s = {12.0};
  s.test.beta_rad = {0.0, kPi / 2.0};
  s.test.revolutions = 24;  // long enough that the Fourier route is the cheaper one
  s.accelerometer.noise = AccelerometerNoise{};
  s.errors.counter_wobble_x_rad.terms.push_back({2, 2e-5, 0.3});
  s.errors.main_wobble_y_rad.terms.push_back({1, 1e-5, -0.7});
  s.errors.radius_error_m = 3e-5;
  SensorChannel c = lone_channel(s.accelerometer);
  c.name = "ax";
  c.output = OutputColumn{"ax_dv", OutputQuantity::kSpecificForce, form, kStandardGravity, 0.0, "m/s"};
  s.imu_channels = {c};
  return s;
}

/// The channel's exact output at time s of the test's timeline (no acquisition delay).
double exact_output(const Scenario& s, const CentrifugeModel& model, const Timeline& timeline, double at) {
  const SensorChannel& c = s.imu_channels.front();
  return sensor_output(c.sensor,
                       channel_inputs(model, platform_motion(model, joint_state_at(timeline, at)), c));
}

/// The integral of the exact output over [a, b] by composite Simpson with 48 panels: a harmonic that turns
/// by 0.3 rad across the interval is integrated to (0.3 / 48)^4 / 180 ~ 1e-11 of its amplitude.
double simpson(const Scenario& s, const CentrifugeModel& model, const Timeline& timeline, double a,
               double b) {
  constexpr int kPanels = 48;
  const double h = (b - a) / kPanels;
  double sum = exact_output(s, model, timeline, a) + exact_output(s, model, timeline, b);
  for (int i = 1; i < kPanels; ++i)
    sum += (i % 2 == 1 ? 4.0 : 2.0) * exact_output(s, model, timeline, a + h * i);
  return sum * h / 3.0;
}

struct Row {
  double t, theta_deg, psi_deg, beta_deg, increment;
};

/// The test's own record of the scenario: every row's increment the Simpson integral of the exact output
/// over the interval that ends at its stamp (the first's over the interval before it), times the column's
/// scale.
std::vector<Row> generate(const Scenario& s) {
  const CentrifugeModel model = s.model();
  const Timeline timeline = make_timeline(s.test, model);
  const double fs = s.test.sample_rate_hz;
  const std::uint64_t n = sample_count(timeline, fs);
  std::vector<Row> rows;
  rows.reserve(n);
  for (std::uint64_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / fs;
    const double before = k == 0 ? -1.0 / fs : static_cast<double>(k - 1) / fs;
    const JointState j = joint_state_at(timeline, t);
    rows.push_back({t, j.main_angle_rad * kRadToDeg, j.counter_angle_rad * kRadToDeg,
                    j.position_angle_rad * kRadToDeg,
                    s.imu_channels.front().output.scale * simpson(s, model, timeline, before, t)});
  }
  return rows;
}

std::string record_text(const std::vector<Row>& rows) {
  std::string text = "time_s,main_angle_deg,counter_angle_deg,position_angle_deg,ax_dv\n";
  for (const Row& r : rows)
    text += fmt::format("{},{},{},{},{}\n", r.t, r.theta_deg, r.psi_deg, r.beta_deg, r.increment);
  return text;
}

Reduction reduce_text(const Scenario& s, const std::string& text) {
  RecordReader reader = RecordReader::from_string(text, s.reading_layout(), "increments.csv");
  std::vector<Reduction> r =
      reduce_record_channels(reader, reduction_plan(s.test, SensorKind::kAccelerometer, s.reduce), s.reduce,
                             s.centrifuge.rate_rad_s);
  EXPECT_EQ(r.size(), 1u);
  return r.front();
}

/// The largest |reduce(data) - reduce(model)| over the positions, g, with the model of `channel` (its
/// true coefficients), by `route`.
double worst_misfit(const Scenario& s, const Reduction& r, const SensorChannel& channel,
                    ModelTermsRoute route = ModelTermsRoute::kExact) {
  const std::vector<PositionModelTerms> terms =
      reduce_sensor_model_terms(r, s.model(), s.reduce, channel, 0, route);
  const Eigen::VectorXd u = std::get<Accelerometer>(channel.sensor).products();
  double worst = 0.0;
  for (std::size_t i = 0; i < r.positions.size(); ++i) {
    const DesignRow& row = terms[i].sensor_exact;
    double y = row.known;
    for (std::size_t k = 0; k < row.size; ++k) y += u[static_cast<Eigen::Index>(k)] * row.regressors[k];
    worst = std::max(worst, std::abs(r.positions[i].mean - y));
  }
  return worst;
}

class IncrementRecord : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scenario_ = new Scenario(increment_scenario(OutputForm::kIncrement));
    rows_ = new std::vector<Row>(generate(*scenario_));
  }
  static void TearDownTestSuite() {
    delete scenario_;
    delete rows_;
  }
  static Scenario* scenario_;
  static std::vector<Row>* rows_;
};
Scenario* IncrementRecord::scenario_ = nullptr;
std::vector<Row>* IncrementRecord::rows_ = nullptr;

TEST_F(IncrementRecord, TheReductionOfDataAndOfTheModelAveragedOverTheIntervalsAgree) {
  const Scenario& s = *scenario_;
  const Reduction r = reduce_text(s, record_text(*rows_));
  ASSERT_EQ(r.positions.size(), 14u);  // 2 beta x 7 gamma
  ASSERT_TRUE(r.increments_dropped.has_value());
  EXPECT_EQ(*r.increments_dropped, 0u);
  // The first harmonic of the centripetal force, g: omega^2 R / g.
  const double first_harmonic = 144.0 * s.centrifuge.radius_m / s.site.gravity_m_s2;
  double largest = 0.0;
  for (const ReducedPosition& p : r.positions) largest = std::max(largest, std::abs(p.mean));
  EXPECT_GT(largest, 0.9 * first_harmonic);
  const SensorChannel& channel = s.imu_channels.front();
  // Both routes of the model's side: the Fourier closed forms and every sample by Gauss-Legendre.
  std::vector<DwellModelTermsRoute> routes;
  reduce_sensor_model_terms(r, s.model(), s.reduce, channel, 0, ModelTermsRoute::kExact, &routes);
  ASSERT_FALSE(routes.empty());
  for (const DwellModelTermsRoute& route : routes) EXPECT_TRUE(route.fourier);
  EXPECT_LT(worst_misfit(s, r, channel), 1e-10 * first_harmonic);
  EXPECT_LT(worst_misfit(s, r, channel, ModelTermsRoute::kEverySample), 1e-10 * first_harmonic);
  // The same data taken for rates at the stamps misses by the half interval's lag of the first harmonic
  // (docs/records.md, "Increments": omega dt / 2 = 0.03 rad, 0.44 g of a 14.7 g first harmonic).
  SensorChannel as_rates = channel;
  as_rates.output.form = OutputForm::kRate;
  const double lag = first_harmonic * 12.0 / s.test.sample_rate_hz / 2.0;
  const double miss = worst_misfit(s, r, as_rates);
  EXPECT_GT(miss, 0.8 * lag);
  EXPECT_LT(miss, 1.05 * lag);
}

TEST_F(IncrementRecord, AGapAndALostRowDropExactlyTheIncrementsWithoutAnInterval) {
  const Scenario& s = *scenario_;
  const Reduction clean = reduce_text(s, record_text(*rows_));
  // Inside the first dwell's measured part: a lost row, and later a clock jump of 0.5 s (a break in the
  // record): the increment after each covers an interval the stamps do not give.
  const Dwell& d = clean.dwells.front();
  const auto row_at = [&](double t) {
    return static_cast<std::size_t>(
        std::lower_bound(rows_->begin(), rows_->end(), t, [](const Row& a, double v) { return a.t < v; }) -
        rows_->begin());
  };
  std::vector<Row> rows = *rows_;
  const std::size_t lost = row_at(d.first_time_s + 0.3 * (d.last_time_s - d.first_time_s));
  const std::size_t jump = row_at(d.first_time_s + 0.7 * (d.last_time_s - d.first_time_s));
  for (std::size_t k = jump; k < rows.size(); ++k) rows[k].t += 0.5;
  rows.erase(rows.begin() + static_cast<std::ptrdiff_t>(lost));
  const Reduction r = reduce_text(s, record_text(rows));
  ASSERT_TRUE(r.increments_dropped.has_value());
  EXPECT_EQ(*r.increments_dropped, 2u);
  EXPECT_EQ(r.dwells.front().quality.increments_dropped, 2u);
  EXPECT_EQ(r.gaps, 2u);
  EXPECT_EQ(r.samples_used, clean.samples_used - 3);  // the lost row and the two dropped
  // What is used still agrees with the model to the same exactness.
  const double first_harmonic = 144.0 * s.centrifuge.radius_m / s.site.gravity_m_s2;
  EXPECT_LT(worst_misfit(s, r, s.imu_channels.front()), 1e-10 * first_harmonic);
  // The same record read as rates (no increment column) drops nothing and says nothing of increments.
  Scenario rates = s;
  rates.imu_channels.front().output.form = OutputForm::kRate;
  const Reduction as_rates = reduce_text(rates, record_text(rows));
  EXPECT_FALSE(as_rates.increments_dropped.has_value());
  EXPECT_EQ(as_rates.samples_used, clean.samples_used - 1);
}

TEST_F(IncrementRecord, TheSimulatorIntegratesEachIntervalAsTheQuadratureDoes) {
  const Scenario& s = *scenario_;
  std::ostringstream out;
  simulate_record(s, SimulationOptions{}, out);
  RecordReader reader = RecordReader::from_string(out.str(), s.reading_layout(), "simulated.csv");
  const double scale = s.imu_channels.front().output.scale;
  const double first_harmonic = 144.0 * s.centrifuge.radius_m / s.site.gravity_m_s2;
  // Where a ramp or a platform's move begins, cruises or ends inside an interval (an acceleration jumps)
  // neither quadrature is exact: the rows compared are the dwells' measured parts, where the motion is
  // smooth.
  const Reduction clean = reduce_text(s, record_text(*rows_));
  const auto smooth = [&](double a, double b) {
    for (const Dwell& d : clean.dwells)
      if (a >= d.first_time_s - 1e-9 && b <= d.last_time_s + 1e-9) return true;
    return false;
  };
  RecordSample sample;
  std::size_t k = 0, compared = 0;
  for (; reader.next(sample); ++k) {
    ASSERT_LT(k, rows_->size());
    const Row& mine = (*rows_)[k];
    ASSERT_EQ(sample.time_s, mine.t);
    if (k == 0) {
      EXPECT_TRUE(std::isnan(sample.outputs[0]));
      continue;
    }
    const double interval = mine.t - (*rows_)[k - 1].t;
    if (!smooth((*rows_)[k - 1].t, mine.t)) continue;
    EXPECT_NEAR(sample.outputs[0], mine.increment / scale / interval, 1e-11 * first_harmonic) << "row " << k;
    ++compared;
  }
  EXPECT_EQ(k, rows_->size());
  EXPECT_GT(compared, 1000u);
}

TEST_F(IncrementRecord, TheSimulatorWritesEveryChannelInItsOwnUnitsAndOrder) {
  // The increment channel, then a gyro written as a rate in mV (2 mV per deg/h, 1 mV at zero input) on the
  // unit's y axis: each column named by the channel, in the channels' order.
  Scenario s = *scenario_;
  SensorChannel gyro = lone_channel(Gyro{});
  std::get<Gyro>(gyro.sensor).noise = GyroNoise{};
  gyro.name = "gy";
  gyro.axes << 0, 0, 1, 1, 0, 0, 0, 1, 0;  // I = y, O = z, S = x
  gyro.output = OutputColumn{"gy_mv", OutputQuantity::kRate, OutputForm::kRate, 2.0, 1.0, "mV"};
  s.imu_channels.push_back(gyro);
  std::ostringstream out;
  simulate_record(s, SimulationOptions{}, out);
  const std::string text = out.str();
  EXPECT_NE(text.find("\ntime_s,main_angle_deg,counter_angle_deg,position_angle_deg,ax_dv,gy_mv\n"),
            std::string::npos);
  RecordReader reader = RecordReader::from_string(text, s.reading_layout(), "simulated.csv");
  ASSERT_EQ(reader.output_count(), 2u);
  const CentrifugeModel model = s.model();
  const Timeline timeline = make_timeline(s.test, model);
  RecordSample sample;
  std::size_t k = 0;
  for (; reader.next(sample); ++k) {
    if (k % 97 != 0) continue;
    // The rate at the stamp, read back through the column's offset and scale (a few roundings).
    const double rate = sensor_output(
        gyro.sensor,
        channel_inputs(model, platform_motion(model, joint_state_at(timeline, sample.time_s)), gyro));
    EXPECT_NEAR(sample.outputs[1], rate, 1e-13 * std::max(1.0, std::abs(rate))) << "row " << k;
    if (k > 0) {
      EXPECT_NEAR(sample.outputs[0],
                  (*rows_)[k].increment / kStandardGravity / ((*rows_)[k].t - (*rows_)[k - 1].t), 1e-6);
    }
  }
  EXPECT_EQ(k, rows_->size());
}

}  // namespace
}  // namespace gyrocal
