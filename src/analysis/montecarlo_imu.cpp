// The Monte Carlo of a whole IMU (analysis/montecarlo_imu.hpp): each trial draws the machine, simulates the
// IMU's record into one reducer of every channel, calibrates it jointly, and compares every estimate with its
// truth.
#include "gyrocal/analysis/montecarlo_imu.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <variant>

#include <fmt/format.h>

#include "gyrocal/analysis/predict_imu.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/parallel.hpp"
#include "gyrocal/core/random.hpp"
#include "gyrocal/identify/imu_calibration.hpp"
#include "gyrocal/identify/misfit.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace gyrocal {
namespace {

/// Welford's running mean and sum of squared deviations of one number over the trials, fed in trial order.
struct Running {
  long long n = 0;
  double mean = 0.0, m2 = 0.0;
  void add(double v) {
    if (!std::isfinite(v)) return;
    ++n;
    const double d = v - mean;
    mean += d / static_cast<double>(n);
    m2 += d * (v - mean);
  }
  double std() const {
    return n > 1 ? std::sqrt(m2 / static_cast<double>(n - 1)) : std::numeric_limits<double>::quiet_NaN();
  }
};

/// The running statistics of one estimate: its error, its stated std, its z-score.
struct EstimateRunning {
  Running error, stated, z;
};

/// What one trial gives per estimate (the channels' coefficients in order, then the errors).
struct TrialValue {
  double error = std::numeric_limits<double>::quiet_NaN();
  double stated = std::numeric_limits<double>::quiet_NaN();
};

/// The true value of each coefficient of a channel, in its sensor's table order and in the units calibrate
/// states them in: a gyro's ten drift coefficients then its rate errors (ppm, arcsec), an accelerometer's
/// eleven with K1 times the channel's output_scale (docs/imu.md).
std::vector<double> coefficient_truth(const SensorChannel& c) {
  std::vector<double> out;
  if (const auto* g = std::get_if<Gyro>(&c.sensor)) {
    out.assign(g->drift.values.begin(), g->drift.values.end());
    out.push_back(g->rate.scale_factor_error_ppm);
    out.push_back(g->rate.input_axis_misalignment_O_arcsec);
    out.push_back(g->rate.input_axis_misalignment_S_arcsec);
    return out;
  }
  const Accelerometer& a = std::get<Accelerometer>(c.sensor);
  out.assign(a.coefficients.values.begin(), a.coefficients.values.end());
  out[static_cast<std::size_t>(AccelCoefficient::K1)] *= c.output.scale;
  return out;
}

/// The distribution of one estimate from its running statistics.
ImuEstimateDistribution distribution(std::string name, std::string unit, double truth, double planned_std,
                                     const EstimateRunning& r) {
  ImuEstimateDistribution d;
  d.name = std::move(name);
  d.unit = std::move(unit);
  d.truth = truth;
  d.trials = r.error.n;
  d.mean = r.error.n > 0 ? r.error.mean : std::numeric_limits<double>::quiet_NaN();
  d.std = r.error.std();
  d.stated_std = r.stated.n > 0 ? r.stated.mean : std::numeric_limits<double>::quiet_NaN();
  d.planned_std = planned_std;
  if (r.z.n > 0) d.z_mean = r.z.mean;
  d.z_std = r.z.std();
  return d;
}

}  // namespace

ImuMonteCarloResult monte_carlo_imu(const Scenario& scenario, const MonteCarloOptions& options) {
  if (!scenario.is_imu()) throw Error("monte_carlo_imu takes an IMU's scenario ([sensor] kind = \"imu\").");
  std::string invalid;
  if (!options.IsValid(&invalid)) throw Error("Monte Carlo options: " + invalid + ".");
  if (options.mode != MonteCarloMode::kSamples)
    throw Error(
        "montecarlo of an IMU runs the samples mode only (--samples: the whole pipeline per trial); the fast "
        "linear mode serves a lone sensor (docs/imu.md, \"What serves an IMU\").");
  if (options.self)
    throw Error(
        "--compensation self is the lone gyro's: an IMU estimates the machine errors of [calibration] "
        "estimate each trial (docs/imu.md).");
  const CalibrationOptions& calibration = options.calibration;

  // The configured unit (identify_imu fits every gyro channel on calibration.gyro_model).
  const Scenario& configured = scenario;
  const std::vector<SensorChannel> channels = configured.channels();
  const CentrifugeModel told = configured.model();

  // The sources, drawn as the lone sensor's trials draw them (prepare_monte_carlo): each [uncertainty] entry
  // in order, then the local gravity.
  std::vector<MonteCarloSource> sources;
  for (const auto& [term, u] : nonzero_error_terms(scenario.uncertainty)) sources.push_back({term, u});
  if (scenario.gravity_uncertainty_m_s2 > 0.0) {
    MachineErrorTerm g;
    g.error = "gravity";
    g.unit = "m/s^2";
    sources.push_back({g, scenario.gravity_uncertainty_m_s2, true});
  }

  // The plan: which coefficients and errors the configured test identifies, and their predicted std (the
  // plan's refusals, an error it cannot separate, come before any trial).
  const ImuCalibrationResult plan = predict_imu_calibration(configured, calibration);
  struct Slot {
    std::size_t channel = 0, index = 0;  ///< a coefficient: its channel and index; an error: channels.size()
  };
  std::vector<Slot> slots;
  ImuMonteCarloResult result;
  result.trials = options.trials;
  result.seed = options.seed;
  result.gyro_model = calibration.gyro_model;
  for (const MonteCarloSource& s : sources) {
    result.sources.push_back(s.term.label());
    result.source_std.push_back(s.std_si / s.term.unit_to_si);
    result.source_units.push_back(s.term.unit);
  }
  std::vector<std::vector<double>> truth(channels.size());
  for (std::size_t c = 0; c < channels.size(); ++c) {
    truth[c] = coefficient_truth(channels[c]);
    ImuChannelDistribution d;
    d.name = channels[c].name;
    d.sensor = kind_of(channels[c].sensor);
    const std::vector<CoefficientEstimate>& planned = plan.channels[c].coefficients;
    if (planned.size() > truth[c].size())
      throw Error(fmt::format("channel {}: {} coefficients planned, {} true values (internal).", d.name,
                              planned.size(), truth[c].size()));
    for (std::size_t k = 0; k < planned.size(); ++k) {
      if (planned[k].identifiable)
        slots.push_back({c, k});
      else
        d.not_identifiable.emplace_back(planned[k].name, planned[k].reason);
    }
    result.channels.push_back(std::move(d));
  }
  for (std::size_t j = 0; j < plan.machine_errors.size(); ++j) {
    const MachineErrorEstimate& e = plan.machine_errors[j];
    if (e.identifiable)
      slots.push_back({channels.size(), j});
    else
      result.not_identifiable.emplace_back(e.parameter.label(), e.reason);
  }
  const std::size_t nv = slots.size();

  std::vector<std::string> columns;
  bool increments = false;
  for (const SensorChannel& c : channels) {
    columns.push_back(c.name);
    increments = increments || c.output.form == OutputForm::kIncrement;
  }
  const TestSpec reduce_plan = reduction_plan(configured.test, reduction_kind(channels), calibration.reduce);

  // Trial k: its estimates' errors and stated stds into out[0..nv).
  const auto trial = [&](std::size_t k, TrialValue* out) {
    RandomSource rng(options.seed, k);
    Scenario drawn = configured;
    for (const MonteCarloSource& s : sources) s.add_to(drawn, s.std_si * rng.normal());
    // Reduced as calibrate reduces the IMU's record: every channel in one pass, an increment's row without
    // an interval left out (the simulator's rows are already in the reader's units: deg/h and g, an increment
    // divided by its interval).
    Reducer reducer(reduce_plan, calibration.reduce, fmt::format("Monte Carlo trial {}", k),
                    drawn.centrifuge.rate_rad_s);
    reducer.set_threaded_accumulation(false);  // the trials already run on every core
    reducer.set_output_columns(columns);
    reducer.set_increments(increments);
    std::vector<OutputRange> ranges(channels.size());
    SimulationOptions so;
    so.seed = rng.next_u64();
    simulate(drawn, so, [&](const RecordSample& sample) {
      for (std::size_t c = 0; c < ranges.size(); ++c) ranges[c].push(sample.outputs[c]);
      reducer.push(sample);
    });
    const ImuCalibrationResult r =
        identify_imu(reducer.finish_channels(), channels, told, calibration, ranges);
    for (std::size_t v = 0; v < nv; ++v) {
      const Slot& s = slots[v];
      if (s.channel < channels.size()) {
        const CoefficientEstimate& e = r.channels[s.channel].coefficients[s.index];
        if (!e.identifiable) continue;
        out[v] = {e.value - truth[s.channel][s.index], e.std};
      } else {
        const MachineErrorEstimate& e = r.machine_errors[s.index];
        if (!e.identifiable) continue;
        out[v] = {e.value - e.parameter.get(drawn.errors) / e.parameter.info().unit_to_si, e.std};
      }
    }
  };

  // Batches of trials on the workers, each trial its own slot; folded in trial order after each batch, so
  // that the result does not depend on the threads and memory does not grow with the trials.
  const auto trials = static_cast<std::size_t>(options.trials);
  const std::size_t batch = 256;
  std::vector<TrialValue> values(std::min(trials, batch) * nv);
  std::vector<EstimateRunning> running(nv);
  std::atomic<std::size_t> done{0};
  const auto tick = [&] {
    if (options.progress) options.progress(static_cast<double>(done.load()) / static_cast<double>(trials));
  };
  for (std::size_t first = 0; first < trials; first += batch) {
    const std::size_t count = std::min(batch, trials - first);
    std::fill(values.begin(), values.end(), TrialValue{});
    parallel_for(
        count, options.threads,
        [&](std::size_t b) {
          try {
            trial(first + b, values.data() + b * nv);
          } catch (const std::exception& e) {
            throw Error(fmt::format("Monte Carlo trial {} (seed {}): {}", first + b, options.seed, e.what()));
          }
          ++done;
        },
        tick);
    for (std::size_t b = 0; b < count; ++b)
      for (std::size_t v = 0; v < nv; ++v) {
        const TrialValue& t = values[b * nv + v];
        if (!std::isfinite(t.error)) continue;
        running[v].error.add(t.error);
        running[v].stated.add(t.stated);
        if (t.stated > 0.0) running[v].z.add(t.error / t.stated);
      }
  }

  for (std::size_t v = 0; v < nv; ++v) {
    const Slot& s = slots[v];
    if (s.channel < channels.size()) {
      const CoefficientEstimate& p = plan.channels[s.channel].coefficients[s.index];
      result.channels[s.channel].coefficients.push_back(
          distribution(p.name, p.unit, truth[s.channel][s.index], p.std, running[v]));
    } else {
      const MachineErrorEstimate& p = plan.machine_errors[s.index];
      result.machine_errors.push_back(
          distribution(p.parameter.label(), p.unit, p.configured, p.std, running[v]));
    }
  }
  if (options.progress) options.progress(1.0);
  return result;
}

}  // namespace gyrocal
