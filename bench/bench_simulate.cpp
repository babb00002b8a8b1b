// Simulation throughput, one core: rows/s of the default scenario's test (docs/physics.md section 11)
// simulated and written as CSV, and the parts of one row (timeline, exact model, noise, formatting) on their
// own.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/atomic_file.hpp"
#include "gyrocal/model/gyro.hpp"
#include "gyrocal/plan/timeline.hpp"
#include "gyrocal/simulate/noise.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace {

namespace fs = std::filesystem;
using namespace gyrocal;

/// The default scenario, its test cut to `revolutions` per dwell.
Scenario scenario(int revolutions) {
  Scenario s = default_scenario();
  s.test.revolutions = revolutions;
  return s;
}

/// The whole default test (200 revolutions per beta: about 108 000 rows, 10 MB) written to a file.
void BM_SimulateRecordToFile(benchmark::State& state) {
  const Scenario s = scenario(200);
  const fs::path path =
      fs::temp_directory_path() / ("gyrocal_bench_simulate_" + std::to_string(::getpid()) + ".csv");
  std::uint64_t rows = 0;
  for (auto _ : state) {
    AtomicOutputFile file(path, true);
    rows += simulate_record(s, {}, file.stream()).samples;
    file.commit();
  }
  state.counters["file_MB"] = static_cast<double>(fs::file_size(path)) / 1e6;
  fs::remove(path);
  state.SetItemsProcessed(static_cast<std::int64_t>(rows));
}
BENCHMARK(BM_SimulateRecordToFile)->Unit(benchmark::kMillisecond);

/// Simulation without any output: the timeline, the exact model, the gyro model and the noise.
void BM_SimulateSamples(benchmark::State& state) {
  const Scenario s = scenario(50);
  std::uint64_t rows = 0;
  double sum = 0.0;
  for (auto _ : state) {
    rows += simulate(s, {}, [&sum](const RecordSample& r) { sum += r.outputs[0]; }).samples;
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(static_cast<std::int64_t>(rows));
}
BENCHMARK(BM_SimulateSamples)->Unit(benchmark::kMillisecond);

/// The joints at one instant (a binary search over the segments and the profiles).
void BM_JointStateAt(benchmark::State& state) {
  const Scenario s = scenario(200);
  const Timeline timeline = make_timeline(s.test, s.model());
  double t = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(joint_state_at(timeline, t));
    t += 0.005;
    if (t >= timeline.duration_s) t = 0.0;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_JointStateAt);

/// One noise sample with the default noise (angle random walk only).
void BM_Noise(benchmark::State& state) {
  const Scenario s = default_scenario();
  GyroNoiseGenerator noise(s.noise, s.test.sample_rate_hz, 1);
  for (auto _ : state) benchmark::DoNotOptimize(noise.next(1.0));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Noise);

}  // namespace

BENCHMARK_MAIN();
