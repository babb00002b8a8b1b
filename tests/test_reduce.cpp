// Reduction of a record that is not clean (docs/physics.md section 14): spikes anywhere in the record, and
// too few revolutions for the scatter between them to be a measurement.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <gtest/gtest.h>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/plan/timeline.hpp"
#include "gyrocal/reduce/dwell_accumulator.hpp"
#include "gyrocal/result/calibration_json.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/rig_record.hpp"

namespace gyrocal {
namespace {

bool sanitized() {
  return std::getenv("GYROCAL_SANITIZED") != nullptr;
}

/// A small default-like test: the default scenario at 50 Hz (32 samples per revolution), 20 revolutions.
Scenario small_test(int revolutions = 20) {
  Scenario s = default_scenario();
  s.test.sample_rate_hz = 50.0;
  s.test.revolutions = revolutions;
  return s;
}

std::vector<RecordSample> record_of(const Scenario& s, std::uint64_t seed) {
  std::vector<RecordSample> rows;
  SimulationOptions so;
  so.seed = seed;
  simulate(s, so, [&](const RecordSample& x) { rows.push_back(x); });
  return rows;
}

struct Calibrated {
  Reduction reduction;
  CalibrationResult result;
};

Calibrated calibrate_rows(const Scenario& s, const std::vector<RecordSample>& rows,
                          const ReduceOptions& ro = {}, Method method = Method::kLeastSquares) {
  Reducer reducer(s.test, ro, "spiked.csv", s.centrifuge.rate_rad_s);
  for (const RecordSample& x : rows) reducer.push(x);
  Calibrated c;
  c.reduction = reducer.finish();
  CalibrationOptions o;
  o.method = method;
  o.reduce = ro;
  c.result = identify(c.reduction, reduce_model_terms(c.reduction, s.model(), ro), s.model(), o);
  return c;
}

/// The index of the first row at or after time t.
std::size_t row_at(const std::vector<RecordSample>& rows, double t) {
  std::size_t i = 0;
  while (i < rows.size() && rows[i].time_s < t) ++i;
  return i;
}

/// Where a spike goes, from the timeline the simulation follows (plan/timeline.hpp): inside the second dwell,
/// in its last revolution (which the scatter between revolutions did not see), in the settle time before it,
/// and in the platform move that leads to it.
std::map<std::string, double> spike_times(const Scenario& s) {
  const Timeline tl = make_timeline(s.test, s.model());
  const MeasurementInterval& m = tl.measurements.at(1);
  const double revolution = 2 * kPi / 9.9;
  return {{"in a dwell", 0.5 * (m.start_s + m.end_s)},
          {"in a dwell's last revolution", m.end_s - 0.3 * revolution},
          {"in the settle time", m.start_s - 0.5 * s.test.settle_s},
          {"in a platform move", m.start_s - s.test.settle_s - 2.0}};
}

TEST(Spikes, OneSampleNeverMovesAnEstimateAndIsCounted) {
  // One sample of +1e6 deg/h (and one of 1e200) anywhere: the estimates stay where the clean record puts them
  // (within a tenth of their uncertainty), so within their uncertainty of the truth; the uncertainties do not
  // change; chi2 stays finite; a spike inside a dwell is counted as its one outlier, one outside none.
  const Scenario s = small_test();
  const std::vector<RecordSample> clean = record_of(s, 3);
  const Calibrated ref = calibrate_rows(s, clean);
  EXPECT_EQ(ref.reduction.outliers, 0u);
  ASSERT_TRUE(std::isfinite(ref.result.chi2));
  for (const auto& [where, t] : spike_times(s)) {
    for (double spike : {1e6, 1e200}) {
      std::vector<RecordSample> rows = clean;
      rows[row_at(rows, t)].outputs[0] = spike;
      const Calibrated c = calibrate_rows(s, rows);
      const std::string tag = where + ", " + std::to_string(spike);
      const bool inside = where.rfind("in a dwell", 0) == 0;
      EXPECT_EQ(c.reduction.outliers, inside ? 1u : 0u) << tag;
      std::size_t counted = 0;
      for (const ReducedPosition& p : c.reduction.positions) counted += p.outliers;
      EXPECT_EQ(counted, inside ? 4u : 0u) << tag;  // the dwell's 4 positions share its one outlier
      const nlohmann::json quality = calibration_to_json(c.result).at("data_quality");
      EXPECT_EQ(quality.at("outliers").get<std::size_t>(), inside ? 1u : 0u) << tag;
      EXPECT_EQ(quality.at("rows_read").get<std::size_t>(), rows.size()) << tag;
      EXPECT_EQ(quality.at("gaps").get<std::size_t>(), 0u) << tag;
      EXPECT_TRUE(std::isfinite(c.result.chi2)) << tag;
      EXPECT_LT(c.result.chi2, 5.0 * (c.result.dof + 3.0 * std::sqrt(2.0 * c.result.dof))) << tag;
      for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
        const CoefficientEstimate& e = c.result.coefficients[k];
        const CoefficientEstimate& e0 = ref.result.coefficients[k];
        ASSERT_EQ(e.identifiable, e0.identifiable) << tag;
        if (!e.identifiable) continue;
        const std::string name = tag + " " + std::string(kCoefficientNames[k]);
        ASSERT_TRUE(std::isfinite(e.value) && std::isfinite(e.std)) << name;
        EXPECT_NEAR(e.std, e0.std, 0.05 * e0.std) << name;
        EXPECT_NEAR(e.value, e0.value, 0.1 * e0.std) << name;
        EXPECT_NEAR(e.value, s.gyro.values[k], 4.0 * e.std) << name;
      }
    }
  }
}

TEST(Spikes, ANoiseFreeRecordWithASpikeIsIdentifiedExactly) {
  // The outlier is replaced by the dwell's fit at its instant, so the reduction operator - the one the
  // model terms go through - is unchanged, and a noise-free record still gives the truth. Several
  // spikes, one of each sign, in two dwells.
  Scenario s = small_test(8);
  s.noise = GyroNoise{};
  std::vector<RecordSample> rows = record_of(s, 1);
  const Timeline tl = make_timeline(s.test, s.model());
  for (int d : {0, 2}) {
    const MeasurementInterval& m = tl.measurements.at(static_cast<std::size_t>(d));
    rows[row_at(rows, m.start_s + 1.0)].outputs[0] += 500.0;
    rows[row_at(rows, m.start_s + 3.0)].outputs[0] -= 2e4;
  }
  const Calibrated c = calibrate_rows(s, rows);
  EXPECT_EQ(c.reduction.outliers, 4u);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    if (c.result.coefficients[k].identifiable) {
      EXPECT_NEAR(c.result.coefficients[k].value, s.gyro.values[k], 1e-6) << kCoefficientNames[k];
    }
  }
}

TEST(Spikes, CleanNoisyRecordsLoseNoSamplesAndKeepTheirEstimates) {
  // Gaussian noise reaches 6 standard deviations once in 5e8 samples: over these records (about 1e5 samples
  // in dwells, both reductions) nothing is rejected, and every estimate and uncertainty is the one without
  // the rule (the rule delays samples but changes none), to the rounding of its sums: with the rule the fit's
  // sums of b b' come from the harmonics' moments, a revolution at a time (HarmonicMoments), without it from
  // each sample's products. A billionth of the std is far below any change of a sample (one in 1e5 moves an
  // estimate by ~3e-3 of its std) and far above that rounding (~1e-12).
  const int seeds = sanitized() ? 3 : 8;
  std::size_t used = 0;
  struct Case {
    double rate_hz;
    ReduceOptions::Method method;
    int order;
  };
  // 13 and 32 samples per revolution for the harmonic fit (order 2 where 13 cannot carry order 3); window
  // means need a sample in every 10 degree window.
  const Case cases[] = {{20.0, ReduceOptions::Method::kHarmonicFit, 2},
                        {50.0, ReduceOptions::Method::kHarmonicFit, 3},
                        {100.0, ReduceOptions::Method::kWindowMean, 3}};
  for (int seed = 0; seed < seeds; ++seed) {
    for (const Case& k : cases) {
      Scenario s = small_test();
      s.test.sample_rate_hz = k.rate_hz;
      const std::vector<RecordSample> rows = record_of(s, 100 + static_cast<std::uint64_t>(seed));
      ReduceOptions with, without;
      with.method = without.method = k.method;
      with.harmonic_order = without.harmonic_order = k.order;
      without.outlier_threshold = 0.0;
      const Calibrated a = calibrate_rows(s, rows, with), b = calibrate_rows(s, rows, without);
      EXPECT_EQ(a.reduction.outliers, 0u) << seed << " " << k.rate_hz;
      used += a.reduction.samples_used;
      for (std::size_t c = 0; c < kNumGyroCoefficients; ++c) {
        if (!b.result.coefficients[c].identifiable) continue;
        const double std = b.result.coefficients[c].std;
        EXPECT_NEAR(a.result.coefficients[c].value, b.result.coefficients[c].value, 1e-9 * std)
            << seed << " " << k.rate_hz;
        EXPECT_NEAR(a.result.coefficients[c].std, std, 1e-9 * std) << seed << " " << k.rate_hz;
      }
    }
  }
  EXPECT_GT(used, sanitized() ? 20000u : 60000u);
}

TEST(DataQuality, RowsUsedAndGapsInsideDwellsAreCounted) {
  // Rows used: the measured parts of the four dwells, 20 revolutions at 50 Hz each (the planned duration,
  // 12.69 s, holds 634 or 635 samples). Two rows missing in one dwell make one gap; one missing in a platform
  // move none.
  const Scenario s = small_test();
  std::vector<RecordSample> rows = record_of(s, 2);
  const Timeline tl = make_timeline(s.test, s.model());
  const std::size_t a = row_at(rows, tl.measurements.at(2).start_s + 4.0);
  rows.erase(rows.begin() + static_cast<std::ptrdiff_t>(a),
             rows.begin() + static_cast<std::ptrdiff_t>(a + 2));
  const std::size_t b = row_at(rows, tl.measurements.at(1).start_s - s.test.settle_s - 2.0);
  rows.erase(rows.begin() + static_cast<std::ptrdiff_t>(b));
  const Calibrated c = calibrate_rows(s, rows);
  EXPECT_EQ(c.result.data_quality.rows_read, rows.size());
  EXPECT_EQ(c.result.data_quality.gaps, 1u);
  EXPECT_GE(c.result.data_quality.rows_used, 4u * 634u - 2u);
  EXPECT_LE(c.result.data_quality.rows_used, 4u * 635u);
  EXPECT_EQ(c.result.data_quality.outliers, 0u);
}

TEST(Spikes, AStaticHoldRejectsASpikeToo) {
  Scenario s = small_test(6);
  s.test.rates_rad_s = {9.9, 0.0};
  s.test.beta_rad = {0.0, kPi / 2};
  s.test.gamma_rad = {0.0, kPi / 2, kPi, 1.5 * kPi};
  const std::vector<RecordSample> clean = record_of(s, 5);
  const Calibrated ref = calibrate_rows(s, clean);
  const Timeline tl = make_timeline(s.test, s.model());
  const MeasurementInterval& hold = tl.measurements.back();
  std::vector<RecordSample> rows = clean;
  rows[row_at(rows, 0.5 * (hold.start_s + hold.end_s))].outputs[0] = -1e6;
  const Calibrated c = calibrate_rows(s, rows);
  EXPECT_EQ(c.reduction.outliers, 1u);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
    if (ref.result.coefficients[k].identifiable) {
      EXPECT_NEAR(c.result.coefficients[k].value, ref.result.coefficients[k].value,
                  0.1 * ref.result.coefficients[k].std)
          << kCoefficientNames[k];
    }
}

/// Gaussian noise of unit variance from a fixed seed (Box-Muller on std::mt19937_64: the same on every
/// platform).
std::vector<double> unit_noise(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 engine(seed);
  std::vector<double> z(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double u1 = (static_cast<double>(engine() >> 11) + 0.5) * 0x1p-53;
    const double u2 = static_cast<double>(engine() >> 11) * 0x1p-53;
    z[i] = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }
  return z;
}

// The rule settles most blocks from bounds of the median and the MAD (a histogram) without computing them
// (docs/calibration.md, "Spikes"); a sample just beyond the threshold must still be found, one just within it
// must not. Noise 0.01 deg/h on harmonics of tens of deg/h, 127 samples a revolution (blocks of two).
TEST(Spikes, ASampleJustBeyondTheThresholdIsFoundOneWithinIsNot) {
  const int per_rev = 127, revolutions = 12;
  const std::size_t n = static_cast<std::size_t>(per_rev * revolutions);
  const double sigma = 0.01, step = 2.0 * kPi / per_rev, dt = 0.005;
  const std::vector<double> z = unit_noise(n, 17);
  const auto run = [&](std::size_t at, double spike_sigmas) {
    DwellAccumulator acc(ReduceOptions{}, {0.0, kPi / 2, kPi, 1.5 * kPi}, false, 1,
                         dt * static_cast<double>(n), true);
    for (std::size_t i = 0; i < n; ++i) {
      const double g = step * static_cast<double>(i);
      double v = 30.0 * std::cos(g) - 12.0 * std::sin(2.0 * g) + 5.0 + sigma * z[i];
      if (i == at) v += spike_sigmas * sigma;
      acc.add(dt * static_cast<double>(i), g, &v);
    }
    return acc.finish(0).outliers;
  };
  EXPECT_EQ(run(n, 0.0), 0u);  // no spike: nothing lost
  // 9 sigma (the MAD of 254 samples is within ~15 % of sigma): an outlier, in the first, a middle and the
  // last block (tested by finish()); 4 sigma: none.
  for (std::size_t at : {std::size_t{40}, n / 2 + 3, n - 5}) {
    const double noise_there = z[at];
    EXPECT_EQ(run(at, 9.0 - noise_there), 1u) << at;
    EXPECT_EQ(run(at, 4.0 - noise_there), 0u) << at;
  }
}

/// The spread of (estimate - truth) / std over seeds, for every identifiable coefficient and combination.
std::map<std::string, double> z_spread(const Scenario& s, int trials, Method method) {
  std::map<std::string, std::vector<double>> z;
  const double omega = 9.9;
  const double ar = omega * s.centrifuge.radius_m *
                    (omega + 2 * s.site.earth_rate_rad_s * std::sin(s.site.latitude_rad)) /
                    s.site.gravity_m_s2;
  const DriftCoefficients& d = s.gyro;
  const std::map<std::string, double> truth = {
      {"dII-dSS", d[Coefficient::dII] - d[Coefficient::dSS]},
      {"dOO-dSS", d[Coefficient::dOO] - d[Coefficient::dSS]},
      {"dF+(1+Ar^2)dSS", d[Coefficient::dF] + (1 + ar * ar) * d[Coefficient::dSS]}};
  std::vector<PositionModelTerms> model_terms;
  for (int trial = 0; trial < trials; ++trial) {
    Reducer reducer(s.test, ReduceOptions{}, "simulated", omega);
    SimulationOptions so;
    so.seed = 5000 + static_cast<std::uint64_t>(trial);
    simulate(s, so, [&](const RecordSample& x) { reducer.push(x); });
    const Reduction red = reducer.finish();
    if (model_terms.empty()) model_terms = reduce_model_terms(red, s.model(), ReduceOptions{});
    CalibrationOptions o;
    o.method = method;
    const CalibrationResult r = identify(red, model_terms, s.model(), o);
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
      if (r.coefficients[k].identifiable)
        z[std::string(kCoefficientNames[k])].push_back((r.coefficients[k].value - d.values[k]) /
                                                       r.coefficients[k].std);
    for (const NamedEstimate& e : r.combinations) z[e.name].push_back((e.value - truth.at(e.name)) / e.std);
  }
  std::map<std::string, double> spread;
  for (const auto& [name, v] : z) {
    double mean = 0, var = 0;
    for (double x : v) mean += x;
    mean /= static_cast<double>(v.size());
    for (double x : v) var += (x - mean) * (x - mean);
    spread[name] = std::sqrt(var / static_cast<double>(v.size() - 1));
  }
  return spread;
}

TEST(Revolutions, FewRevolutionsGiveHonestUncertainties) {
  // With 3, 4 or 6 revolutions per dwell the standard errors come from 1, 2 or 4 degrees of freedom per
  // gamma; the uncertainties must still describe the spread of the estimates: z has unit standard deviation
  // (0.85..1.15; 250 trials pin it to +-0.05). The sanitizer build runs the same 250: records are
  // bit-identical on every build, so it checks the same numbers (with 120 trials and 54 checks, one fell
  // outside 0.8..1.2 by chance).
  const int trials = 250;
  for (int revolutions : {3, 4, 6}) {
    for (Method method : {Method::kLeastSquares, Method::kClosedForm}) {
      Scenario s = small_test(revolutions);
      s.test.sample_rate_hz = 40.0;
      s.test.settle_s = 0.5;
      const std::map<std::string, double> spread = z_spread(s, trials, method);
      EXPECT_EQ(spread.size(), 9u);
      std::string line;
      for (const auto& [name, sd] : spread) line += " " + name + " " + std::to_string(sd).substr(0, 5);
      std::printf("std of z, %d revolutions, %s:%s\n", revolutions, to_string(method).c_str(), line.c_str());
      for (const auto& [name, sd] : spread) {
        EXPECT_GT(sd, 0.85) << revolutions << " revolutions, " << name;
        EXPECT_LT(sd, 1.15) << revolutions << " revolutions, " << name;
      }
    }
  }
}

TEST(Revolutions, TooFewForAScatterIsARefusalSayingHowManyAreNeeded) {
  Scenario s = small_test(2);
  const std::vector<RecordSample> rows = record_of(s, 1);
  try {
    calibrate_rows(s, rows);
    FAIL() << "two revolutions leave no degree of freedom for the scatter about a line";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("revolutions"), std::string::npos) << m;
    EXPECT_NE(m.find("at least 3"), std::string::npos) << m;
  }
}

TEST(RecordEnd, ARecordThatEndsRightAfterASettleTimeIsRefusedWithItsReason) {
  // The rows after a run's settle time wait for two windows to agree before the run is matched to the plan
  // (docs/calibration.md): a record that ends in between must give the dwell's reason, never touch a dwell
  // that was not started. The second dwell follows a position move (its first window may hold the move's
  // end); the record is cut at many instants after its settle time.
  const Scenario s = small_test(20);
  const Timeline tl = make_timeline(s.test, s.model());
  ASSERT_GE(tl.measurements.size(), 2u);
  const MeasurementInterval& second = tl.measurements[1];
  const std::vector<RecordSample> rows = record_of(s, 1);
  for (double after_s = 0.0; after_s < 0.6; after_s += 0.04) {
    Reducer reducer(s.test, ReduceOptions{}, "cut.csv", s.centrifuge.rate_rad_s);
    for (const RecordSample& x : rows) {
      if (x.time_s > second.start_s + after_s) break;
      reducer.push(x);
    }
    try {
      reducer.finish();
      FAIL() << "a record of less than two dwells cannot give every position";
    } catch (const Error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(fmt::format("position {} (", second.position_index)), std::string::npos) << m;
      EXPECT_NE(m.find("the record ends"), std::string::npos) << after_s << ": " << m;
    }
  }
}

// ---- Records as a rig writes them (docs/physics.md section 14; tests/support/rig_record.hpp)
// -------------------

/// A two-speed test of 8 dwells (every coefficient identifiable), short enough for many seeds.
Scenario rig_scenario() {
  Scenario s = default_scenario();
  s.test.sample_rate_hz = 50.0;
  s.test.revolutions = 8;
  s.test.rates_rad_s = {9.9, 7.0};
  return s;
}

std::vector<RecordSample> rig_record(const Scenario& s, const testing::RigImperfections& imp,
                                     std::uint64_t seed) {
  std::vector<testing::RigRow> rows;
  testing::rig_rows(s, imp, testing::RigMotion{}, seed, [&](const testing::RigRow& r) { rows.push_back(r); });
  return testing::as_samples(rows);
}

/// Every imperfection of docs/physics.md section 14 at the level the reduction must take.
std::map<std::string, testing::RigImperfections> rig_cases() {
  std::map<std::string, testing::RigImperfections> c;
  c["perfect"] = {};
  c["jitter"].jitter_s = 1e-4;
  c["stamps rounded to ms"].jitter_s = 1e-4, c["stamps rounded to ms"].stamp_resolution_s = 1e-3;
  c["quantised angles"].angle_quantum_deg = 0.1, c["quantised angles"].position_count_deg = 0.002;
  c["rate offset"].rate_offset = 1e-3;
  c["ripple"].ripple = 2e-4;
  c["gap"].gap_fraction = 0.1;
  c["clock jump"].clock_jump_s = 1000.0;
  c["spikes"].spikes = 6;
  c["beta glitch"].beta_glitch_deg = 30.0;
  const testing::RigImperfections all = testing::every_imperfection();
  c["all together"] = all;
  return c;
}

TEST(RigRecord, EachImperfectionAloneAndAllTogetherCalibrateToTheTruth) {
  const Scenario s = rig_scenario();
  for (const auto& [name, imp] : rig_cases()) {
    const std::vector<RecordSample> rows = rig_record(s, imp, 11);
    Calibrated c;
    try {
      c = calibrate_rows(s, rows);
    } catch (const Error& e) {
      ADD_FAILURE() << name << ": " << e.what();
      continue;
    }
    EXPECT_EQ(c.reduction.dwells.size(), 8u) << name;
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
      const CoefficientEstimate& e = c.result.coefficients[k];
      ASSERT_TRUE(e.identifiable) << name << " " << kCoefficientNames[k];
      EXPECT_NEAR(e.value, s.gyro.values[k], 4.0 * e.std) << name << " " << kCoefficientNames[k];
    }
    const DataQuality& q = c.result.data_quality;
    EXPECT_EQ(q.rows_read, rows.size()) << name;
    // Spikes in the measured parts are outliers; those in ramps, moves and settle times reach nothing.
    if (imp.spikes > 0) {
      EXPECT_GE(q.outliers, 1u) << name;
      EXPECT_LE(q.outliers, static_cast<std::size_t>(imp.spikes)) << name;
    } else {
      EXPECT_EQ(q.outliers, 0u) << name;
    }
    const std::size_t gaps = (imp.gap_fraction > 0 ? 1u : 0u) + (imp.clock_jump_s > 0 ? 1u : 0u);
    EXPECT_EQ(q.gaps, gaps) << name;
    EXPECT_EQ(c.reduction.encoder_glitch_rows, imp.beta_glitch_deg != 0 ? 1u : 0u) << name;
    // The result JSON says per dwell what was dropped and why (docs/contract.md, data_quality).
    const nlohmann::json dq = calibration_to_json(c.result).at("data_quality");
    ASSERT_EQ(dq.at("dwells").size(), 8u) << name;
    std::size_t glitches = 0, used = 0;
    for (const nlohmann::json& d : dq.at("dwells")) {
      glitches += d.at("dropped").at("encoder_glitches").get<std::size_t>();
      used += d.at("rows_used").get<std::size_t>();
      EXPECT_GT(d.at("dropped").at("settle").get<std::size_t>(), 0u) << name;
      EXPECT_FALSE(d.at("ended").get<std::string>().empty()) << name;
    }
    EXPECT_EQ(glitches, c.reduction.encoder_glitch_rows) << name;
    EXPECT_EQ(used, q.rows_used) << name;
  }
}

TEST(RigRecord, UncertaintiesDescribeTheSpreadOverSeeds) {
  // Every imperfection at once: over >= 50 seeds (estimate - truth) / std has a standard deviation in
  // 0.85..1.15 for every coefficient.
  const Scenario s = rig_scenario();
  const testing::RigImperfections all = rig_cases().at("all together");
  const int seeds = sanitized() ? 100 : 250;
  std::vector<std::vector<double>> z(kNumGyroCoefficients);
  // No good record is refused (a refusal throws here: docs/calibration.md, "When the residuals misfit");
  // one in a thousand may have its std scaled by chance.
  int scaled = 0;
  for (int seed = 0; seed < seeds; ++seed) {
    const Calibrated c = calibrate_rows(s, rig_record(s, all, 1000 + static_cast<std::uint64_t>(seed)));
    scaled += c.result.misfit.scale > 1.0;
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
      z[k].push_back((c.result.coefficients[k].value - s.gyro.values[k]) / c.result.coefficients[k].std);
  }
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    double mean = 0, var = 0;
    for (double x : z[k]) mean += x;
    mean /= static_cast<double>(z[k].size());
    for (double x : z[k]) var += (x - mean) * (x - mean);
    const double sd = std::sqrt(var / static_cast<double>(z[k].size() - 1));
    std::printf("rig record, std of z for %s: %.3f (mean %.3f)\n", std::string(kCoefficientNames[k]).c_str(),
                sd, mean);
    EXPECT_GT(sd, 0.85) << kCoefficientNames[k];
    EXPECT_LT(sd, 1.15) << kCoefficientNames[k];
  }
  std::printf("rig record: %d of %d records had their std scaled for a misfit\n", scaled, seeds);
  EXPECT_LE(scaled, 2);
}

TEST(RigRecord, BeyondItsToleranceARecordIsRefusedNamingThePositionTheTimeAndTheReason) {
  const Scenario s = rig_scenario();
  struct Case {
    std::string name;
    testing::RigImperfections imp;
    std::string reason;
  };
  std::vector<Case> cases(3);
  cases[0].name = "beta moves 0.4 deg";
  cases[0].imp.beta_move_in_dwell_deg = 0.4;
  cases[0].reason = "beta moves by 0.4 deg at t = ";
  cases[1].name = "rate 5e-3 off";
  cases[1].imp.rate_offset = 5e-3;
  cases[1].reason = "(relative) from the planned 9.9 rad/s";
  cases[2].name = "ripple 5e-3";
  cases[2].imp.ripple = 5e-3;
  cases[2].reason = "the rate changes by";
  for (const Case& k : cases) {
    try {
      calibrate_rows(s, rig_record(s, k.imp, 3));
      ADD_FAILURE() << k.name << ": calibrated";
    } catch (const Error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("position "), std::string::npos) << k.name << ": " << m;
      EXPECT_NE(m.find("the steady run at t = "), std::string::npos) << k.name << ": " << m;
      EXPECT_NE(m.find(k.reason), std::string::npos) << k.name << ": " << m;
    }
  }
}

TEST(Exactness, ANoiseFreeTwoSpeedRecordWithLargeMachineErrorsIsExactByDefault) {
  // docs/physics.md section 4: W_red = omega_red + sum c_j x_j,red holds after reduction when the model's
  // model terms go through the data's operator on the data's samples. With a lever arm of 1 cm, runouts,
  // wobbles to harmonic 3 and position-platform errors, a strided model term grid left 4.3e-6 deg/h/g^2 on
  // dOS.
  Scenario s = small_test(8);
  s.test.sample_rate_hz = 200.0;  // 127 samples per revolution: a strided grid would skip samples
  s.test.rates_rad_s = {9.9, 7.0};
  s.noise = GyroNoise{};
  CentrifugeErrors& e = s.errors;
  e.lever_arm_m = Eigen::Vector3d(0.01, -0.01, 0.01);
  e.main_runout_x_m.terms = {{1, 2e-4, 0.3}, {2, 1e-4, 1.0}, {3, 5e-5, 2.0}};
  e.main_runout_y_m.terms = {{1, 1.5e-4, 0.7}, {3, 5e-5, 0.1}};
  e.main_wobble_x_rad.terms = {{1, 2e-4, 0.2}, {2, 1e-4, 0.4}, {3, 5e-5, 0.9}};
  e.counter_wobble_y_rad.terms = {{1, 2e-4, 1.2}, {2, 1e-4, 0.5}, {3, 5e-5, 2.5}};
  e.position_wobble_x_rad.terms = {{1, 1e-4, 0.3}, {3, 5e-5, 1.1}};
  e.position_perpendicularity_x_rad = 2e-4;
  e.position_angle_error_rad = 3e-4;
  const std::vector<RecordSample> rows = record_of(s, 1);
  const Calibrated c = calibrate_rows(s, rows);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    ASSERT_TRUE(c.result.coefficients[k].identifiable) << kCoefficientNames[k];
    EXPECT_NEAR(c.result.coefficients[k].value, s.gyro.values[k], 1e-7) << kCoefficientNames[k];
  }
  // The configuration is one that a strided model term grid (the former default, 32 per revolution) does not
  // reduce exactly: the test can tell.
  ReduceOptions strided;
  strided.model_samples_per_revolution = 32;
  const Calibrated b = calibrate_rows(s, rows, strided);
  double worst = 0.0;
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
    worst = std::max(worst, std::abs(b.result.coefficients[k].value - s.gyro.values[k]));
  std::printf("strided channel grid: largest coefficient error %.3g\n", worst);
  EXPECT_GT(worst, 1e-7);
}

}  // namespace
}  // namespace gyrocal
