#include "gyrocal/simulate/simulator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/core/random.hpp"
#include "gyrocal/model/gyro.hpp"
#include "gyrocal/model/machine_errors.hpp"
#include "gyrocal/record/increments.hpp"
#include "gyrocal/sensor/channel.hpp"
#include "gyrocal/sensor/sensor.hpp"
#include "gyrocal/simulate/accelerometer_noise.hpp"
#include "gyrocal/simulate/noise.hpp"

namespace gyrocal {
namespace {

constexpr std::uint64_t kProgressEverySamples = 4096;

/// An encoder's reading of an angle (rad): degrees in [0, 360).
double encoder_deg(double angle_rad) {
  const double deg = angle_rad * kRadToDeg;
  double wrapped = deg - 360.0 * std::floor(deg / 360.0);  // exact floor; rounding may leave -0 ... 360
  if (wrapped < 0.0) wrapped += 360.0;
  return wrapped >= 360.0 ? 0.0 : wrapped;
}

/// Degrees to 15 significant digits: reads as typed (270, not 270.00000000000006).
std::string degrees(double angle_rad) {
  return fmt::format("{:.15g}", angle_rad * kRadToDeg);
}

std::string list(const std::vector<double>& values, double scale) {
  std::string s = "[";
  for (std::size_t i = 0; i < values.size(); ++i) {
    s += (i ? ", " : "") + (scale == 1.0 ? fmt::format("{}", values[i]) : degrees(values[i]));
  }
  return s + "]";
}

/// The sensor's noise: the gyro's in deg/h, the accelerometer's referred to its input and scaled by K1.
using NoiseGenerator = std::variant<GyroNoiseGenerator, AccelerometerNoiseGenerator>;

/// The scenario's channels (at most limits::kMaxOutputColumns, a record's outputs) and a noise generator for
/// each. The first channel's stream is seeded with `seed`, so that a lone sensor's record is what it always
/// was; each further channel's with derive_stream_seed(seed, its number), so that the channels' noises are
/// independent.
std::vector<SensorChannel> record_channels(const Scenario& scenario, double fs, std::uint64_t seed,
                                           std::vector<NoiseGenerator>& noise) {
  std::vector<SensorChannel> channels = scenario.channels();
  if (channels.size() > limits::kMaxOutputColumns)
    throw Error(fmt::format("A record holds at most {} channels (limits::kMaxOutputColumns), not {}.",
                            limits::kMaxOutputColumns, channels.size()));
  noise.clear();
  for (std::size_t k = 0; k < channels.size(); ++k) {
    const std::uint64_t s = k == 0 ? seed : derive_stream_seed(seed, k);
    if (const auto* a = std::get_if<Accelerometer>(&channels[k].sensor))
      noise.emplace_back(std::in_place_type<AccelerometerNoiseGenerator>, a->noise,
                         a->coefficients[AccelCoefficient::K1], fs, s);
    else
      noise.emplace_back(std::in_place_type<GyroNoiseGenerator>, std::get<Gyro>(channels[k].sensor).noise, fs,
                         s);
  }
  return channels;
}

/// How the channels written as increments are integrated over each row's interval (docs/records.md,
/// "Increments"): the Gauss-Legendre rule of record/increments.hpp, its nodes enough for 1e-13 on a harmonic
/// of twice the model route's first band (2 max(12, 8 x the errors' highest harmonic + 4)) of the test's
/// fastest joint (twice its fastest main rate plus a counter offset) over one sample interval. No rule (nodes
/// empty) when no channel is an increment.
IntervalRule increment_rule(const Scenario& scenario, const std::vector<SensorChannel>& channels) {
  bool any = false;
  for (const SensorChannel& c : channels) any = any || c.output.form == OutputForm::kIncrement;
  if (!any) return {};
  int highest = 0;
  for (const MachineErrorField& f : machine_error_fields()) {
    if (f.kind != MachineErrorKind::kSeries) continue;
    for (const HarmonicTerm& term : (scenario.errors.*f.series).terms)
      if (term.amplitude != 0.0) highest = std::max(highest, std::abs(term.harmonic));
  }
  double fastest = 0.0, offset = 0.0;
  for (double r : scenario.test.rates_rad_s) fastest = std::max(fastest, std::abs(r));
  for (double o : scenario.test.counter_rate_offsets_rad_s) offset = std::max(offset, std::abs(o));
  const double band = 2.0 * std::max(12, 8 * highest + 4);
  return interval_rule(interval_nodes(band * (2.0 * fastest + offset) / scenario.test.sample_rate_hz));
}

/// The row at time t (the k-th, t = k / fs): the encoders' readings and each channel's output with its
/// generator's next noise. A channel written as increments gets the mean of its noise-free output over the
/// row's interval [t - dt, t] (dt = t less the previous row's time, 1 / fs before the first), by `rule`, plus
/// its generator's noise for the row (white noise per sample is the mean of a rate's white noise over the
/// interval: the same variance).
void sample_at(const CentrifugeModel& model, const std::vector<SensorChannel>& channels,
               const Timeline& timeline, double t, std::vector<NoiseGenerator>& noise, RecordSample& sample,
               const IntervalRule& rule = {}, double interval_s = 0.0) {
  const JointState joints = joint_state_at(timeline, t);
  // The output stamped at t was sensed the acquisition's delay earlier ([record] output_delay_s): the
  // machine's own motion at that instant (the encoders are read at t). The platform's motion once, then
  // each channel's inputs at its mount and on its axes.
  const double delay_s = model.errors().output_delay_s;
  const PlatformFrameMotion motion =
      platform_motion(model, delay_s == 0.0 ? joints : joint_state_at(timeline, t - delay_s));
  sample.time_s = t;
  sample.main_angle_deg = encoder_deg(joints.main_angle_rad);
  sample.counter_angle_deg = encoder_deg(joints.counter_angle_rad);
  sample.position_angle_deg = encoder_deg(joints.position_angle_rad);
  // Each sensor's noise-free output at its exact inputs (Gyro: docs/physics.md sections 6 and 15, the
  // sensed rate (1 + e)(omega_I + dO omega_O + dS omega_S) plus the drift, omega_I bit for bit with no rate
  // errors; Accelerometer: docs/accelerometer.md's IEEE 1293 model), then its noise.
  for (std::size_t k = 0; k < channels.size(); ++k) {
    if (channels[k].output.form == OutputForm::kIncrement) continue;
    const double clean = sensor_output(channels[k].sensor, channel_inputs(model, motion, channels[k]));
    sample.outputs[k] = std::visit([clean](auto& generator) { return generator.next(clean); }, noise[k]);
  }
  if (rule.back.empty()) return;
  // The increments: the exact output at every node of the interval (the motion at each, once for all
  // channels), never the rate at the stamp.
  std::array<double, limits::kMaxOutputColumns> mean{};
  for (std::size_t n = 0; n < rule.back.size(); ++n) {
    const double at = t - delay_s - rule.back[n] * interval_s;
    const PlatformFrameMotion m = platform_motion(model, joint_state_at(timeline, at));
    for (std::size_t k = 0; k < channels.size(); ++k)
      if (channels[k].output.form == OutputForm::kIncrement)
        mean[k] += rule.weight[n] * sensor_output(channels[k].sensor, channel_inputs(model, m, channels[k]));
  }
  for (std::size_t k = 0; k < channels.size(); ++k) {
    if (channels[k].output.form != OutputForm::kIncrement) continue;
    const double clean = mean[k];
    sample.outputs[k] = std::visit([clean](auto& generator) { return generator.next(clean); }, noise[k]);
  }
}

/// A row as an IMU's record writes it (docs/records.md): each channel's column in its own units, reading =
/// offset + scale x value, an increment's value times the row's interval.
RecordSample in_column_units(const std::vector<SensorChannel>& channels, RecordSample sample,
                             double interval_s) {
  for (std::size_t k = 0; k < channels.size(); ++k) {
    const OutputColumn& o = channels[k].output;
    const double value =
        o.form == OutputForm::kIncrement ? sample.outputs[k] * interval_s : sample.outputs[k];
    sample.outputs[k] = o.offset + o.scale * value;
  }
  return sample;
}

/// The interval that ends at the k-th row's stamp k / fs: the stamp less the previous one (1 / fs for the
/// first row, whose interval lies before the test).
double row_interval(std::uint64_t k, double fs) {
  const double t = static_cast<double>(k) / fs;
  return k == 0 ? 1.0 / fs : t - static_cast<double>(k - 1) / fs;
}

/// The record's writer: a lone sensor's gyrocal format (its native column), an IMU's with one column per
/// channel.
RecordWriter make_writer(std::ostream& out, const Scenario& scenario,
                         const std::vector<SensorChannel>& channels, const RecordMetadata& metadata) {
  if (scenario.is_imu()) {
    std::vector<OutputColumn> columns;
    for (const SensorChannel& c : channels) columns.push_back(c.output);
    return RecordWriter(out, metadata, columns, {});
  }
  const std::string_view column =
      std::visit([](const auto& s) { return s.native_column; }, scenario.sensor());
  return RecordWriter(out, metadata, {}, column);
}

/// The simulation loop; `sink` is a template parameter so that the record writer's call is direct. It takes
/// each row (outputs in the sensors' units, an increment's as the mean over its interval) and the row's
/// interval, s.
template <typename Sink>
SimulationSummary run(const Scenario& scenario, const Timeline& timeline, std::uint64_t seed,
                      const SimulationOptions& options, Sink&& sink) {
  const CentrifugeModel model = scenario.model();
  const double fs = scenario.test.sample_rate_hz;
  std::vector<NoiseGenerator> noise;
  const std::vector<SensorChannel> channels = record_channels(scenario, fs, seed, noise);
  const IntervalRule rule = increment_rule(scenario, channels);
  const std::uint64_t n = sample_count(timeline, fs);
  RecordSample sample;
  for (std::uint64_t k = 0; k < n; ++k) {
    const double interval_s = row_interval(k, fs);
    sample_at(model, channels, timeline, static_cast<double>(k) / fs, noise, sample, rule, interval_s);
    sink(sample, interval_s);
    if (options.progress && (k + 1) % kProgressEverySamples == 0) {
      options.progress(static_cast<double>(k + 1) / static_cast<double>(n));
    }
  }
  if (options.progress) options.progress(1.0);
  return {n, timeline.duration_s, seed};
}

}  // namespace

RecordMetadata simulation_metadata(const Scenario& scenario, const Timeline& timeline, std::uint64_t seed) {
  const TestSpec& test = scenario.test;
  const GyroNoise& noise = scenario.noise;
  RecordMetadata m = {
      {"generator", "gyrocal simulate"},
      {"seed", fmt::format("{}", seed)},
      {"sample_rate_hz", fmt::format("{}", test.sample_rate_hz)},
      {"settle_s", fmt::format("{}", test.settle_s)},
      {"revolutions", fmt::format("{}", test.revolutions)},
      {"rates_rad_s", list(test.rates_rad_s, 1.0)},
      {"beta_deg", list(test.beta_rad, kRadToDeg)},
      {"gamma_deg", list(test.gamma_rad, kRadToDeg)},
      {"hold_s", fmt::format("{}", timeline.hold_s)},
      {"reference_rate_rad_s", fmt::format("{}", timeline.reference_rate_rad_s)},
      {"radius_m", fmt::format("{}", scenario.centrifuge.radius_m)},
      {"latitude_deg", degrees(scenario.site.latitude_rad)},
      {"gravity_m_s2", fmt::format("{}", scenario.site.gravity_m_s2)},
      {"earth_rate_rad_s", fmt::format("{}", scenario.site.earth_rate_rad_s)},
      {"heading_deg", degrees(scenario.centrifuge.heading_rad)},
      {"initial_main_angle_deg", degrees(scenario.centrifuge.initial_main_angle_rad)},
      {"angles", "encoder readings in deg, wrapped to [0, 360)"},
      {"duration_s", fmt::format("{}", timeline.duration_s)},
      {"samples", fmt::format("{}", sample_count(timeline, test.sample_rate_hz))},
  };
  // The acquisition's delay ([record] output_delay_s), written only where there is one, so that a plain
  // record is what it always was.
  if (scenario.errors.output_delay_s != 0.0)
    m.emplace_back("output_delay_s", fmt::format("{}", scenario.errors.output_delay_s));
  if (scenario.is_imu()) {
    // An IMU's record: its channels, each as name:column:form (the configuration holds their truth).
    std::string channels;
    for (const SensorChannel& c : scenario.imu_channels)
      channels += fmt::format("{}{}:{}:{}", channels.empty() ? "" : ", ", c.name, c.output.column,
                              c.output.form == OutputForm::kIncrement ? "increment" : "rate");
    m.emplace_back("sensor", "imu");
    m.emplace_back("channels", "[" + channels + "]");
    return m;
  }
  if (scenario.sensor_kind == SensorKind::kAccelerometer) {
    // An accelerometer's record: its kind, noise ([accelerometer.noise] keys) and truth (parameter table).
    const Accelerometer& a = scenario.accelerometer;
    m.emplace_back("sensor", std::string(Accelerometer::kind));
    // The output column holds the sensor's output, K1 per g (docs/records.md, "An accelerometer's record"):
    // in g only when K1 is 1. `noise` divides by it to state the noise referred to the input, in ug.
    m.emplace_back("output_scale_per_g", fmt::format("{}", a.coefficients[AccelCoefficient::K1]));
    for (const AccelerometerNoiseKey& key : kAccelerometerNoiseKeys)
      m.emplace_back(fmt::format("noise_{}", key.key), fmt::format("{}", a.noise.*key.member));
    for (std::size_t i = 0; i < kNumAccelCoefficients; ++i)
      m.emplace_back(fmt::format("truth_{}", kAccelerometerParameters[i].name),
                     fmt::format("{}", a.coefficients.values[i]));
    return m;
  }
  m.insert(m.end(),
           {
               {"noise_angle_random_walk_deg_rt_h", fmt::format("{}", noise.angle_random_walk_deg_rt_h)},
               {"noise_bias_instability_deg_h", fmt::format("{}", noise.bias_instability_deg_h)},
               {"noise_rate_random_walk_deg_h_rt_h", fmt::format("{}", noise.rate_random_walk_deg_h_rt_h)},
               {"noise_quantization_deg_h", fmt::format("{}", noise.quantization_deg_h)},
               {"noise_output_lag_s", fmt::format("{}", noise.output_lag_s)},
           });
  for (std::size_t i = 0; i < kNumGyroCoefficients; ++i) {
    m.emplace_back(fmt::format("truth_{}", kCoefficientNames[i]), fmt::format("{}", scenario.gyro.values[i]));
  }
  // The rate-platform method (docs/physics.md section 15), written only where it is used, so that a plain
  // test's record is what it always was.
  if (test.counter_rate_offsets_rad_s != std::vector<double>{0.0})
    m.emplace_back("counter_rate_offsets_rad_s", list(test.counter_rate_offsets_rad_s, 1.0));
  if (!scenario.gyro_rate.is_zero()) {
    const GyroRateErrors& e = scenario.gyro_rate;
    const double values[kNumRateTerms] = {e.scale_factor_error_ppm, e.input_axis_misalignment_O_arcsec,
                                          e.input_axis_misalignment_S_arcsec};
    for (std::size_t i = 0; i < kNumRateTerms; ++i)
      m.emplace_back(fmt::format("truth_{}", kRateTermNames[i]), fmt::format("{}", values[i]));
  }
  return m;
}

SimulationSummary simulate(const Scenario& scenario, const SimulationOptions& options,
                           const SampleSink& sink) {
  const Timeline timeline = make_timeline(scenario.test, scenario.model());
  return run(scenario, timeline, options.seed.value_or(scenario.test.seed), options,
             [&sink](const RecordSample& s, double) { sink(s); });
}

SimulationSummary simulate_written(const Scenario& scenario, const SimulationOptions& options,
                                   const SampleSink& sink) {
  const Timeline timeline = make_timeline(scenario.test, scenario.model());
  const std::vector<SensorChannel> channels = scenario.channels();
  const bool imu = scenario.is_imu();
  return run(scenario, timeline, options.seed.value_or(scenario.test.seed), options,
             [&](const RecordSample& s, double interval_s) {
               if (imu)
                 sink(in_column_units(channels, s, interval_s));
               else
                 sink(s);
             });
}

SimulationSummary simulate_record(const Scenario& scenario, const SimulationOptions& options,
                                  std::ostream& out) {
  const Timeline timeline = make_timeline(scenario.test, scenario.model());
  const std::uint64_t seed = options.seed.value_or(scenario.test.seed);
  const std::vector<SensorChannel> channels = scenario.channels();
  RecordWriter writer = make_writer(out, scenario, channels, simulation_metadata(scenario, timeline, seed));
  const bool imu = scenario.is_imu();
  const SimulationSummary summary =
      run(scenario, timeline, seed, options, [&](const RecordSample& s, double interval_s) {
        if (imu)
          writer.write(in_column_units(channels, s, interval_s));
        else
          writer.write(s);
      });
  writer.finish();
  return summary;
}

RecordSize estimate_record_size(const Scenario& scenario) {
  const Timeline timeline = make_timeline(scenario.test, scenario.model());
  const double fs = scenario.test.sample_rate_hz;
  RecordSize size;
  size.rows = sample_count(timeline, fs);
  size.duration_s = timeline.duration_s;
  // The head exactly, then up to kSampledRows rows spread evenly over the test, written as simulate writes
  // them: the mean row's length times the rows.
  constexpr std::uint64_t kSampledRows = 2000;
  std::ostringstream head;
  make_writer(head, scenario, scenario.channels(),
              simulation_metadata(scenario, timeline, scenario.test.seed))
      .finish();
  const std::uint64_t stride = std::max<std::uint64_t>(1, size.rows / kSampledRows);
  std::ostringstream rows;
  RecordWriter writer = make_writer(rows, scenario, scenario.channels(), {});
  const std::size_t rows_head = rows.str().size();
  const CentrifugeModel model = scenario.model();
  std::vector<NoiseGenerator> noise;
  const std::vector<SensorChannel> channels = record_channels(scenario, fs, scenario.test.seed, noise);
  const IntervalRule rule = increment_rule(scenario, channels);
  RecordSample sample;
  std::uint64_t written = 0;
  for (std::uint64_t k = 0; k < size.rows; k += stride, ++written) {
    const double interval_s = row_interval(k, fs);
    sample_at(model, channels, timeline, static_cast<double>(k) / fs, noise, sample, rule, interval_s);
    writer.write(scenario.is_imu() ? in_column_units(channels, sample, interval_s) : sample);
  }
  writer.finish();
  const auto row_bytes = static_cast<double>(rows.str().size() - rows_head);
  size.bytes =
      head.str().size() +
      (written == 0 ? 0
                    : static_cast<std::uint64_t>(std::llround(row_bytes / static_cast<double>(written) *
                                                              static_cast<double>(size.rows))));
  return size;
}

}  // namespace gyrocal
