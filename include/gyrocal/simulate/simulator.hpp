#pragma once
// Simulation of a whole test (issue 3; docs/physics.md sections 4 and 6): for each sample k at t_k = k / fs
// over the timeline of plan/timeline.hpp, the joints -> the exact inputs -> the gyro's static model with the
// truth coefficients -> the noise of [gyro.noise] -> one row of the record (record/record.hpp).
//
// Encoder angles are written as the joints' angles in degrees wrapped to [0, 360), as an encoder reads them
// (theta, psi_r relative to the arm, beta as commanded). Rows stream out one at a time, so memory does not
// depend on the length of the test. The same scenario and seed give the same rows bit for bit.
#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/plan/timeline.hpp"
#include "gyrocal/record/record.hpp"

namespace gyrocal {

struct SimulationOptions {
  std::optional<std::uint64_t> seed;  ///< the noise's seed; default: the scenario's test.seed
  /// Called with the fraction of samples done, in [0, 1]: every 4096 samples and once at the end with 1.
  std::function<void(double fraction)> progress;
};

struct SimulationSummary {
  std::uint64_t samples = 0;  ///< rows produced
  double duration_s = 0.0;    ///< duration of the test (the timeline), s
  std::uint64_t seed = 0;     ///< the seed used
};

/// Receives each simulated row, in time order.
using SampleSink = std::function<void(const RecordSample&)>;

/// The record's `# key = value` metadata for a simulation of `scenario` with `seed`: generator, seed,
/// sample_rate_hz, settle_s, revolutions, rates_rad_s, beta_deg, gamma_deg (lists as "[a, b]"), hold_s,
/// reference_rate_rad_s, radius_m, latitude_deg, heading_deg, initial_main_angle_deg, angles (how encoder
/// angles are written), duration_s, samples, the noise parameters (noise_<key of [gyro.noise]>) and the truth
/// (truth_dF ... truth_dOS, in the units of docs/physics.md section 1). Numbers are in their shortest exact
/// form, angles in degrees to 15 significant digits.
RecordMetadata simulation_metadata(const Scenario& scenario, const Timeline& timeline, std::uint64_t seed);

/// Simulates every sample of the scenario's test (timeline with the default MotionLimits) and hands each
/// row to `sink`. Throws Error for a test that cannot be planned or invalid noise parameters.
SimulationSummary simulate(const Scenario& scenario, const SimulationOptions& options,
                           const SampleSink& sink);

/// simulate() with each row as simulate_record writes it: an IMU's outputs in its columns' own units (offset
/// + output_scale x value, an increment as the value times its row's interval, docs/records.md), in
/// RecordSample::outputs in the channels' order; a lone sensor's rows as simulate() gives them (deg/h, or g).
/// Throws Error as simulate() does.
SimulationSummary simulate_written(const Scenario& scenario, const SimulationOptions& options,
                                   const SampleSink& sink);

/// What `simulate` would write for the scenario's test, without simulating it (plan prints it): its rows, its
/// duration, s, and its size, bytes: the metadata and header exactly, the rows as the mean length of up to
/// 2000 rows simulated at instants spread evenly over the test (the rows' numbers take their shortest exact
/// form, whose length varies by a few characters) times their number.
struct RecordSize {
  std::uint64_t rows = 0;
  double duration_s = 0.0;
  std::uint64_t bytes = 0;
};
RecordSize estimate_record_size(const Scenario& scenario);

/// Simulates the scenario's test into a record (metadata, header, rows) written to `out`. Throws Error as
/// simulate() does, or if writing fails.
SimulationSummary simulate_record(const Scenario& scenario, const SimulationOptions& options,
                                  std::ostream& out);

}  // namespace gyrocal
