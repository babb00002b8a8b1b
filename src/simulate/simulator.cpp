#include "gyrocal/simulate/simulator.hpp"

#include <algorithm>
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

/// The row at time t: the encoders' readings and each channel's output with its generator's next noise.
void sample_at(const CentrifugeModel& model, const std::vector<SensorChannel>& channels,
               const Timeline& timeline, double t, std::vector<NoiseGenerator>& noise, RecordSample& sample) {
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
    const double clean = sensor_output(channels[k].sensor, channel_inputs(model, motion, channels[k]));
    sample.outputs[k] = std::visit([clean](auto& generator) { return generator.next(clean); }, noise[k]);
  }
}

/// The simulation loop; `sink` is a template parameter so that the record writer's call is direct.
template <typename Sink>
SimulationSummary run(const Scenario& scenario, const Timeline& timeline, std::uint64_t seed,
                      const SimulationOptions& options, Sink&& sink) {
  const CentrifugeModel model = scenario.model();
  const double fs = scenario.test.sample_rate_hz;
  std::vector<NoiseGenerator> noise;
  const std::vector<SensorChannel> channels = record_channels(scenario, fs, seed, noise);
  const std::uint64_t n = sample_count(timeline, fs);
  RecordSample sample;
  for (std::uint64_t k = 0; k < n; ++k) {
    sample_at(model, channels, timeline, static_cast<double>(k) / fs, noise, sample);
    sink(sample);
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
  return run(scenario, timeline, options.seed.value_or(scenario.test.seed), options, sink);
}

SimulationSummary simulate_record(const Scenario& scenario, const SimulationOptions& options,
                                  std::ostream& out) {
  const Timeline timeline = make_timeline(scenario.test, scenario.model());
  const std::uint64_t seed = options.seed.value_or(scenario.test.seed);
  const std::string_view column =
      std::visit([](const auto& s) { return s.native_column; }, scenario.sensor());
  RecordWriter writer(out, simulation_metadata(scenario, timeline, seed), {}, column);
  const SimulationSummary summary =
      run(scenario, timeline, seed, options, [&writer](const RecordSample& s) { writer.write(s); });
  writer.finish();
  return summary;
}

RecordSize estimate_record_size(const Scenario& scenario) {
  const Timeline timeline = make_timeline(scenario.test, scenario.model());
  const double fs = scenario.test.sample_rate_hz;
  RecordSize size;
  size.rows = sample_count(timeline, fs);
  size.duration_s = timeline.duration_s;
  const std::string_view column =
      std::visit([](const auto& s) { return s.native_column; }, scenario.sensor());
  // The head exactly, then up to kSampledRows rows spread evenly over the test, written as simulate writes
  // them: the mean row's length times the rows.
  constexpr std::uint64_t kSampledRows = 2000;
  std::ostringstream head;
  RecordWriter(head, simulation_metadata(scenario, timeline, scenario.test.seed), {}, column).finish();
  const std::uint64_t stride = std::max<std::uint64_t>(1, size.rows / kSampledRows);
  std::ostringstream rows;
  RecordWriter writer(rows, {}, {}, column);
  const std::size_t rows_head = rows.str().size();
  const CentrifugeModel model = scenario.model();
  std::vector<NoiseGenerator> noise;
  const std::vector<SensorChannel> channels = record_channels(scenario, fs, scenario.test.seed, noise);
  RecordSample sample;
  std::uint64_t written = 0;
  for (std::uint64_t k = 0; k < size.rows; k += stride, ++written) {
    sample_at(model, channels, timeline, static_cast<double>(k) / fs, noise, sample);
    writer.write(sample);
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
