// gyrocal noise on a long static record (issue target: 10 million samples in under 5 s and 200 MB).
// The record (white noise plus rate random walk at 100 Hz, ~730 MB) is written once to the temporary folder;
// the benchmark times characterise_record_noise() on it, reading included, and reports the process's peak
// memory. Run alone: other benchmarks in the same process would count in the peak.
#include <sys/resource.h>

#include <filesystem>
#include <fstream>

#include <benchmark/benchmark.h>

#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/simulate/noise.hpp"

namespace fs = std::filesystem;

namespace {

double peak_resident_mb() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // KiB on Linux
}

fs::path static_record(std::size_t rows) {
  const fs::path path = fs::temp_directory_path() / ("gyrocal-bench-noise-" + std::to_string(rows) + ".csv");
  if (fs::exists(path)) return path;
  gyrocal::GyroNoise noise;
  noise.angle_random_walk_deg_rt_h = 0.01;
  noise.rate_random_walk_deg_h_rt_h = 0.5;
  gyrocal::GyroNoiseGenerator generator(noise, 100.0, 1);
  std::ofstream out(path);
  gyrocal::RecordWriter writer(out, {}, {});
  gyrocal::RecordSample sample;
  for (std::size_t i = 0; i < rows; ++i) {
    sample.time_s = static_cast<double>(i) / 100.0;
    sample.outputs[0] = generator.next(12345.0);  // a sensor's offset: the sums must not lose its digits
    writer.write(sample);
  }
  writer.finish();
  return path;
}

void BM_NoiseOfRecord(benchmark::State& state) {
  const fs::path path = static_record(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    const gyrocal::RecordNoise r = gyrocal::characterise_record_noise(path);
    benchmark::DoNotOptimize(r.noise.allan.deviation.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.counters["file_MB"] = static_cast<double>(fs::file_size(path)) / 1e6;
  state.counters["peak_MB"] = peak_resident_mb();
  fs::remove(path);
}
BENCHMARK(BM_NoiseOfRecord)->Arg(10'000'000)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
