#include "gyrocal/analysis/montecarlo.hpp"
#include "gyrocal/core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "gyrocal/analysis/estimates.hpp"
#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/random.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/reduce/dwell_accumulator.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace gyrocal {
namespace {

/// The estimates of a calibration, as errors: (value - true value) per name, in `names` order; an estimate
/// missing from `r` is NaN. The estimates and their true values are analysis/estimates.hpp's, for any sensor
/// (with the gyro model drift+rate, the identifiable rate errors too, docs/physics.md section 15). Fills
/// names, units, truth when `names` is empty; `stated_std` (when given) gets the standard uncertainty the
/// calibration states for each, NaN where missing.
std::vector<double> estimate_errors(const CalibrationResult& r, const Scenario& truth,
                                    std::vector<std::string>& names, std::vector<std::string>* units,
                                    std::vector<double>* true_values,
                                    std::vector<double>* stated_std = nullptr) {
  const std::vector<FlatEstimate> entries = flatten_estimates(r, truth);
  if (names.empty()) {
    for (const FlatEstimate& e : entries) {
      names.push_back(e.name);
      if (units) units->push_back(e.unit);
      if (true_values) true_values->push_back(e.truth);
    }
  }
  std::vector<double> out(names.size(), std::numeric_limits<double>::quiet_NaN());
  if (stated_std) stated_std->assign(names.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < names.size(); ++i)
    for (const FlatEstimate& e : entries)
      if (e.name == names[i]) {
        out[i] = e.value - e.truth;
        if (stated_std) (*stated_std)[i] = e.std;
      }
  return out;
}

/// True when the dwells of a and b lie on the same encoder lines at the same samples: a calibration then
/// evaluates the same model terms on both.
bool same_encoder_lines(const Reduction& a, const Reduction& b) {
  if (a.dwells.size() != b.dwells.size()) return false;
  for (std::size_t i = 0; i < a.dwells.size(); ++i) {
    const Dwell &x = a.dwells[i], &y = b.dwells[i];
    if (x.first_time_s != y.first_time_s || x.samples != y.samples ||
        x.sample_interval_s != y.sample_interval_s || x.main.at_first_rad != y.main.at_first_rad ||
        x.main.rate_rad_s != y.main.rate_rad_s || x.counter.at_first_rad != y.counter.at_first_rad ||
        x.counter.rate_rad_s != y.counter.rate_rad_s)
      return false;
  }
  return true;
}

/// Mean, M2 (sum of squared deviations), min, max of a chunk of trials, per estimate.
struct ChunkStats {
  std::vector<double> mean, m2, lo, hi;
  long long n = 0;
};

}  // namespace

std::string to_string(MonteCarloMode mode) {
  return mode == MonteCarloMode::kFast ? "fast" : "samples";
}

bool MonteCarloOptions::IsValid(std::string* error) const {
  std::string e;
  if (trials < 2)
    e = "at least 2 trials are needed";
  else if (histogram_bins < 1)
    e = "histogram_bins must be at least 1";
  else if (threads < 0)
    e = "threads must not be negative";
  else if (!calibration.IsValid(&e))
    e = "calibration: " + e;
  if (e.empty()) return true;
  if (error) *error = e;
  return false;
}

void MonteCarloSource::add_to(Scenario& s, double amount_si) const {
  if (gravity)
    s.site.gravity_m_s2 += amount_si;
  else
    term.add_to(s.errors, amount_si);
}

MonteCarloModel prepare_monte_carlo(const Scenario& scenario, const MonteCarloOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw Error("Monte Carlo options: " + error + ".");
  MonteCarloModel m;
  m.scenario = scenario;
  m.calibration = options.calibration;
  m.told = scenario;
  if (options.self) {
    m.calibration.method = Method::kLeastSquares;
    m.calibration.compensation = Compensation::kFull;
    m.calibration.estimate = parse_machine_error_names(kSelfCalibratedErrors, "compensation self");
    for (const MachineErrorParameter& e : m.calibration.estimate) e.set(m.told.errors, 0.0);
  }
  for (const auto& [term, u] : nonzero_error_terms(scenario.uncertainty)) m.sources.push_back({term, u});
  if (scenario.gravity_uncertainty_m_s2 > 0.0) {
    // The local gravity: the record is taken under the drawn g, the calibration told the configured one
    // (an accelerometer reads the radius as omega^2 R / g: R0 u_g / g of radius, docs/montecarlo.md).
    MachineErrorTerm g;
    g.error = "gravity";
    g.unit = "m/s^2";
    m.sources.push_back({g, scenario.gravity_uncertainty_m_s2, true});
  }
  const ReduceOptions& ro = options.calibration.reduce;

  const bool gyro = scenario.sensor_kind == SensorKind::kGyro;
  m.calibration.sensor = scenario.sensor_kind;
  if (scenario.record) m.calibration.output_unit = scenario.record->column_unit();  // K1's unit
  if (!gyro && options.self)
    throw Error(
        "Monte Carlo: compensation self is the gyro's; for an accelerometer, --estimate in calibrate and "
        "plan "
        "estimates machine errors from its data (docs/accelerometer.md).");
  const CentrifugeModel model0 = m.told.model();
  // The planned test of `s`'s machine with its outputs and std errors, and (`with_model_terms`) the model
  // terms of `told` on its dwells: the gyro's (predict.hpp), or another sensor's reduced as its record would
  // be (estimates.hpp). `told_is_true`: `told` is `s`'s own machine, whose model terms give the outputs too.
  const auto planned = [&](const Scenario& s, const CentrifugeModel& told, bool with_model_terms,
                           bool told_is_true) {
    if (!gyro) return planned_sensor_test(s, told, ro);
    PlannedSensorTest p;
    p.reduction = planned_reduction(s);
    const std::vector<PositionModelTerms> truth =
        told_is_true ? std::vector<PositionModelTerms>{} : reduce_model_terms(p.reduction, s.model(), ro);
    if (with_model_terms || told_is_true) p.model_terms = reduce_model_terms(p.reduction, told, ro);
    set_noise_free_outputs(p.reduction, told_is_true ? p.model_terms : truth, scenario.gyro,
                           scenario.gyro_rate);
    set_predicted_std_errors(p.reduction, s.noise, s.test.sample_rate_hz, ro);
    return p;
  };
  const GyroNoise noise = output_noise(scenario);

  // The configured machine: its reduction, model terms (what the compensation knows), outputs, std errors.
  // (The outputs are the true machine's: the told one differs under "self".)
  PlannedSensorTest p0 = planned(scenario, model0, true, !options.self);
  const Reduction& r0 = p0.reduction;
  const std::vector<PositionModelTerms>& ch0 = p0.model_terms;
  const auto np = static_cast<Eigen::Index>(r0.positions.size());
  m.positions = static_cast<int>(np);

  // The identification is affine in the outputs W: errors = bias + M (W - W0).
  const auto identify_at = [&](const Eigen::VectorXd& dw) {
    Reduction r = r0;
    for (Eigen::Index i = 0; i < np; ++i) r.positions[static_cast<std::size_t>(i)].mean += dw[i];
    return identify(r, ch0, model0, m.calibration);
  };
  const CalibrationResult configured = identify_at(Eigen::VectorXd::Zero(np));
  m.bias = estimate_errors(configured, scenario, m.names, &m.units, &m.truth, &m.stated_std);
  // A coefficient the plan cannot identify has no distribution; it is said why: the gyro's rate errors carry
  // their reason (docs/physics.md section 15), an accelerometer's (one speed: K0, K2, Kpp, Koo) the
  // combinations that remain, which are among the estimates. A gyro's drift coefficient is named through
  // its combinations.
  for (const CoefficientEstimate& c : configured.coefficients) {
    if (c.identifiable) continue;
    if (!c.reason.empty())
      m.not_identifiable.emplace_back(c.name, c.reason);
    else if (configured.sensor != SensorKind::kGyro)
      m.not_identifiable.emplace_back(
          c.name,
          "the plan does not identify it; the combinations that remain are estimated "
          "(docs/accelerometer.md, \"Test design\").");
  }
  // Compensation "self" (docs/self_calibration.md): a machine error the plan cannot estimate stays at zero in
  // every trial, and its effect moves the estimates (their mean error); it is named with the reason, never
  // left to a mean error nobody explains.
  for (const MachineErrorEstimate& e : configured.machine_errors)
    if (!e.identifiable)
      m.not_identifiable.emplace_back(
          e.error,
          fmt::format("{} Under compensation self it stays at zero, so the estimates above carry the "
                      "effect of its true value (their mean error).",
                      e.reason));
  const auto ne = static_cast<Eigen::Index>(m.names.size());
  Eigen::MatrixXd map(ne, np);
  // Affine in W: the unknowns are linear in the reduced outputs (identify/unknowns.hpp); the misalignments'
  // division by (1 + e) bends it by e's change per deg/h of output, parts per million of theirs.
  // Another sensor's coefficients are ratios of its products (an accelerometer's Kx = u_x / K1): M is their
  // derivative, by a central difference of 1e-4 g (times K1) of each output, exact to ~1e-8 of itself.
  const double step = gyro ? 1.0 : 1e-4 * std::abs(scenario.accelerometer.coefficients[AccelCoefficient::K1]);
  for (Eigen::Index k = 0; k < np; ++k) {
    const std::vector<double> e = estimate_errors(identify_at(step * Eigen::VectorXd::Unit(np, k)), scenario,
                                                  m.names, nullptr, nullptr);
    if (gyro) {
      for (Eigen::Index i = 0; i < ne; ++i)
        map(i, k) = e[static_cast<std::size_t>(i)] - m.bias[static_cast<std::size_t>(i)];
      continue;
    }
    const std::vector<double> d = estimate_errors(identify_at(-step * Eigen::VectorXd::Unit(np, k)), scenario,
                                                  m.names, nullptr, nullptr);
    for (Eigen::Index i = 0; i < ne; ++i)
      map(i, k) = (e[static_cast<std::size_t>(i)] - d[static_cast<std::size_t>(i)]) / (2.0 * step);
  }

  // Each source's effect on the estimates at one standard uncertainty, (E(e0 + u) - E(e0 - u)) / 2, exact to
  // second order: the drawn machine reduced on its own planned encoder lines, as a record of it would be.
  // Where the drawn machine's encoder lines are the configured one's, the calibration sees the same model
  // terms and the effect is the affine map of the outputs' change. Where they differ (counter_rate_mismatch
  // turns the platform's heading, which its encoder measures), a record's calibration evaluates the
  // configured model on the drawn lines: the model terms follow the heading, and the effect is that whole
  // calibration's (docs/montecarlo.md, "The sources through the encoders").
  const auto ns = static_cast<Eigen::Index>(m.sources.size());
  Eigen::MatrixXd effect(ne, ns);
  parallel_for(static_cast<std::size_t>(ns), options.threads, [&](std::size_t s) {
    Eigen::VectorXd side[2];
    for (int k = 0; k < 2; ++k) {
      Scenario drawn = scenario;
      m.sources[s].add_to(drawn, (k == 0 ? 1.0 : -1.0) * m.sources[s].std_si);
      // The drawn machine's outputs; the model terms of the configured machine on its encoder lines.
      PlannedSensorTest p = planned(drawn, model0, false, false);
      const Reduction& r = p.reduction;
      if (static_cast<Eigen::Index>(r.positions.size()) != np)
        throw Error("Monte Carlo: a drawn machine changes the plan.");
      if (same_encoder_lines(r, r0)) {
        Eigen::VectorXd dw(np);
        for (Eigen::Index i = 0; i < np; ++i)
          dw[i] =
              r.positions[static_cast<std::size_t>(i)].mean - r0.positions[static_cast<std::size_t>(i)].mean;
        side[k] = map * dw;
      } else {
        if (p.model_terms.empty()) p.model_terms = reduce_model_terms(r, model0, ro);
        const std::vector<double> e = estimate_errors(identify(r, p.model_terms, model0, m.calibration),
                                                      scenario, m.names, nullptr, nullptr);
        side[k] = Eigen::Map<const Eigen::VectorXd>(e.data(), ne) -
                  Eigen::Map<const Eigen::VectorXd>(m.bias.data(), ne);
      }
    }
    effect.col(static_cast<Eigen::Index>(s)) = 0.5 * (side[0] - side[1]);
  });

  // The gyro's noise through the reduction as a factor L of its covariance, n = L xi: white noise, bias
  // instability and rate random walk, within and across dwells (predict.hpp, docs/noise.md).
  const Eigen::MatrixXd noise_covariance =
      predicted_noise_position_covariance(r0, ro, noise, scenario.test.sample_rate_hz);
  Eigen::MatrixXd chol = Eigen::MatrixXd::Zero(np, np);
  if (!noise_covariance.isZero(0.0)) {
    const Eigen::LLT<Eigen::MatrixXd> llt(noise_covariance);
    if (llt.info() == Eigen::Success) {
      chol = llt.matrixL();
    } else {
      // Without white noise the covariance may be singular (a random walk common to all positions): a
      // symmetric square root instead.
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(noise_covariance);
      if (eigen.info() != Eigen::Success ||
          eigen.eigenvalues().minCoeff() < -1e-9 * eigen.eigenvalues().maxCoeff())
        throw Error("Monte Carlo: the noise covariance is not positive semi-definite.");
      chol = eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
    }
  }
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> g(ne, ns + np);
  g.leftCols(ns) = effect;
  g.rightCols(np) = map * chol;
  m.gain.assign(g.data(), g.data() + g.size());
  return m;
}

MonteCarloResult run_monte_carlo(const MonteCarloModel& m, const MonteCarloOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw Error("Monte Carlo options: " + error + ".");
  const std::size_t ne = m.names.size(), nc = m.columns(), ns = m.sources.size();
  const bool fast = options.mode == MonteCarloMode::kFast;
  // Values per trial: the estimates' errors, and in the samples mode their z-scores against the standard
  // uncertainty each trial's calibration states (the fast mode's is the configured calibration's, fixed).
  const std::size_t nv = fast ? ne : 2 * ne;
  const auto trials = static_cast<std::size_t>(options.trials);

  // The samples mode's fixed parts: the configured model the calibration knows.
  const CentrifugeModel model0 = m.told.model();

  // Trial k's estimate errors into out[0..ne), in the samples mode their z-scores into out[ne..2 ne).
  const auto trial = [&](std::size_t k, double* out) {
    RandomSource rng(options.seed, k);
    if (fast) {
      double xi[256];
      std::vector<double> big;
      double* x = xi;
      if (nc > 256) {
        big.resize(nc);
        x = big.data();
      }
      for (std::size_t c = 0; c < nc; ++c) x[c] = rng.normal();
      for (std::size_t i = 0; i < ne; ++i) {
        const double* row = m.gain.data() + i * nc;
        double v = m.bias[i];
        for (std::size_t c = 0; c < nc; ++c) v += row[c] * x[c];
        out[i] = v;
      }
      return;
    }
    // The same draws of the machine errors as the fast mode, then the whole pipeline.
    Scenario s = m.scenario;
    for (std::size_t c = 0; c < ns; ++c) m.sources[c].add_to(s, m.sources[c].std_si * rng.normal());
    // Reduced as calibrate reduces the sensor's record (an accelerometer's spinning dwells to their whole
    // harmonic content).
    Reducer reducer(reduction_plan(s.test, s.sensor_kind, m.calibration.reduce), m.calibration.reduce,
                    "Monte Carlo trial", s.centrifuge.rate_rad_s);
    reducer.set_threaded_accumulation(false);  // the trials already run on every core
    SimulationOptions so;
    so.seed = rng.next_u64();
    simulate(s, so, [&](const RecordSample& sample) { reducer.push(sample); });
    const Reduction r = reducer.finish();
    const auto model_terms =
        s.sensor_kind == SensorKind::kGyro
            ? reduce_model_terms(r, model0, m.calibration.reduce)
            : reduce_sensor_model_terms(r, model0, m.calibration.reduce, s.channels().front());
    std::vector<std::string> names = m.names;
    std::vector<double> stated;
    const std::vector<double> e = estimate_errors(identify(r, model_terms, model0, m.calibration), m.scenario,
                                                  names, nullptr, nullptr, &stated);
    std::copy(e.begin(), e.end(), out);
    for (std::size_t i = 0; i < ne; ++i)
      out[ne + i] = stated[i] > 0.0 ? e[i] / stated[i] : std::numeric_limits<double>::quiet_NaN();
  };

  // Chunks of trials in a fixed partition: statistics are combined in chunk order, so they do not depend
  // on which thread ran which chunk. The chunks run in batches that are folded before the next starts, so
  // that memory does not grow with the number of trials (the samples mode keeps every trial's errors for
  // its histograms).
  const std::size_t chunk = fast ? 4096 : 8;
  const std::size_t chunks = (trials + chunk - 1) / chunk;
  const std::size_t batch = 1024;
  std::vector<ChunkStats> stats(std::min(chunks, batch));
  std::vector<double> stored(fast ? 0 : trials * nv);
  std::atomic<std::size_t> done{0};
  const double passes = fast ? 2.0 : 1.0;
  const auto tick = [&] {
    if (options.progress)
      options.progress(
          std::min(1.0, static_cast<double>(done.load()) / (passes * static_cast<double>(trials))));
  };
  // Chan et al.'s pairwise update, chunk by chunk in order, per estimate.
  double n_all = 0;
  std::vector<double> mean_all(nv, 0.0), m2_all(nv, 0.0), lo_all(nv, std::numeric_limits<double>::infinity()),
      hi_all(nv, -std::numeric_limits<double>::infinity());
  for (std::size_t first = 0; first < chunks; first += batch) {
    const std::size_t count = std::min(batch, chunks - first);
    parallel_for(
        count, options.threads,
        [&](std::size_t b) {
          const std::size_t c = first + b;
          const std::size_t begin = c * chunk, end = std::min(trials, begin + chunk);
          std::vector<double> values((end - begin) * nv);
          for (std::size_t k = begin; k < end; ++k) trial(k, values.data() + (k - begin) * nv);
          ChunkStats& st = stats[b];
          st.n = static_cast<long long>(end - begin);
          st.mean.assign(nv, 0.0);
          st.m2.assign(nv, 0.0);
          st.lo.assign(nv, std::numeric_limits<double>::infinity());
          st.hi.assign(nv, -std::numeric_limits<double>::infinity());
          for (std::size_t i = 0; i < nv; ++i) {
            for (std::size_t k = 0; k < end - begin; ++k) st.mean[i] += values[k * nv + i];
            st.mean[i] /= static_cast<double>(st.n);
            for (std::size_t k = 0; k < end - begin; ++k) {
              const double v = values[k * nv + i];
              st.m2[i] += (v - st.mean[i]) * (v - st.mean[i]);
              st.lo[i] = std::min(st.lo[i], v);
              st.hi[i] = std::max(st.hi[i], v);
            }
          }
          if (!fast)
            std::copy(values.begin(), values.end(), stored.begin() + static_cast<std::ptrdiff_t>(begin * nv));
          done += end - begin;
        },
        tick);
    for (std::size_t b = 0; b < count; ++b) {
      const ChunkStats& st = stats[b];
      const auto nb = static_cast<double>(st.n);
      const double total = n_all + nb;
      for (std::size_t i = 0; i < nv; ++i) {
        const double delta = st.mean[i] - mean_all[i];
        mean_all[i] += delta * nb / total;
        m2_all[i] += st.m2[i] + delta * delta * n_all * nb / total;
        lo_all[i] = std::min(lo_all[i], st.lo[i]);
        hi_all[i] = std::max(hi_all[i], st.hi[i]);
      }
      n_all = total;
    }
  }

  MonteCarloResult result;
  result.trials = options.trials;
  result.mode = options.mode;
  result.seed = options.seed;
  result.method = m.calibration.method;
  result.self = !m.calibration.estimate.empty();
  result.compensation = m.calibration.compensation;
  result.gyro_model = m.calibration.gyro_model;
  result.not_identifiable = m.not_identifiable;
  result.sensor = m.scenario.sensor_kind;
  result.sources.push_back("noise");
  if (result.sensor == SensorKind::kGyro) {
    result.source_std.push_back(m.scenario.noise.angle_random_walk_deg_rt_h);
    result.source_units.push_back("deg/sqrt(h)");
  } else {
    result.source_std.push_back(m.scenario.accelerometer.noise.velocity_random_walk_ug_rt_hz);
    result.source_units.push_back("ug/sqrt(Hz)");
  }
  for (const MonteCarloSource& s : m.sources) {
    result.sources.push_back(s.term.label());
    result.source_std.push_back(s.std_si / s.term.unit_to_si);
    result.source_units.push_back(s.term.unit);
  }
  const int bins = options.histogram_bins;
  for (std::size_t i = 0; i < ne; ++i) {
    EstimateDistribution d;
    d.name = m.names[i];
    d.unit = m.units[i];
    d.truth = m.truth[i];
    d.predicted_mean = m.bias[i];
    double lo = lo_all[i], hi = hi_all[i];
    d.mean = mean_all[i];
    d.std = std::sqrt(m2_all[i] / (n_all - 1));
    // The z-scores (error / the stated standard uncertainty): the samples mode's per trial; the fast mode's
    // against the configured calibration's stated std, the same in every trial.
    d.stated_std = m.stated_std[i];
    if (!fast) {
      d.z_mean = mean_all[ne + i];
      d.z_std = std::sqrt(m2_all[ne + i] / (n_all - 1));
    } else if (d.stated_std > 0.0) {
      d.z_mean = d.mean / d.stated_std;
      d.z_std = d.std / d.stated_std;
    }
    if (!(hi > lo)) {
      const double pad = std::max(std::abs(lo) * 1e-6, 1e-12);
      lo -= pad;
      hi += pad;
    }
    for (int b = 0; b <= bins; ++b) d.edges.push_back(lo + (hi - lo) * b / bins);
    d.counts.assign(static_cast<std::size_t>(bins), 0);
    // The budget: each column's variance through G; a source's share is its columns' part of the total.
    std::vector<double> var(ns + 1, 0.0);
    for (std::size_t c = 0; c < nc; ++c) {
      const double gc = m.gain[i * nc + c];
      var[c < ns ? c + 1 : 0] += gc * gc;
    }
    double total = 0;
    for (double v : var) total += v;
    d.predicted_std = std::sqrt(total);
    for (double v : var) d.budget.push_back(total > 0 ? v / total : 0.0);
    result.estimates.push_back(std::move(d));
  }

  // Histograms: integer counts, so the order of summation does not matter. The fast mode draws its trials
  // again rather than keeping them.
  const auto bin_of = [&](std::size_t i, double v) {
    const EstimateDistribution& d = result.estimates[i];
    const double x = (v - d.edges.front()) / (d.edges.back() - d.edges.front()) * bins;
    return static_cast<std::size_t>(std::clamp(static_cast<int>(std::floor(x)), 0, bins - 1));
  };
  if (fast) {
    std::vector<std::vector<long long>> counts(std::min(chunks, batch));
    for (std::size_t first = 0; first < chunks; first += batch) {
      const std::size_t count = std::min(batch, chunks - first);
      parallel_for(
          count, options.threads,
          [&](std::size_t b) {
            const std::size_t c = first + b;
            const std::size_t begin = c * chunk, end = std::min(trials, begin + chunk);
            counts[b].assign(ne * static_cast<std::size_t>(bins), 0);
            std::vector<double> v(ne);
            for (std::size_t k = begin; k < end; ++k) {
              trial(k, v.data());
              for (std::size_t i = 0; i < ne; ++i)
                ++counts[b][i * static_cast<std::size_t>(bins) + bin_of(i, v[i])];
            }
            done += end - begin;
          },
          tick);
      for (std::size_t b = 0; b < count; ++b)
        for (std::size_t i = 0; i < ne; ++i)
          for (int k = 0; k < bins; ++k)
            result.estimates[i].counts[static_cast<std::size_t>(k)] +=
                counts[b][i * static_cast<std::size_t>(bins) + static_cast<std::size_t>(k)];
    }
  } else {
    for (std::size_t k = 0; k < trials; ++k)
      for (std::size_t i = 0; i < ne; ++i) ++result.estimates[i].counts[bin_of(i, stored[k * nv + i])];
  }
  if (options.progress) options.progress(1.0);
  return result;
}

MonteCarloResult monte_carlo(const Scenario& scenario, const MonteCarloOptions& options) {
  return run_monte_carlo(prepare_monte_carlo(scenario, options), options);
}

}  // namespace gyrocal
