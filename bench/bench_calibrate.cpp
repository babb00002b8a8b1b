// End-to-end calibration throughput: `calibrate` on a simulated record file, MB/s of CSV on one core, and
// the process's peak memory (issue: >= 150 MB/s; a 10-million-row record under 64 MB, flat in the length).
// The record has GYROCAL_BENCH_ROWS rows (default 2 million; 10 million for the memory figure):
//   bench_calibrate --benchmark_filter=Calibrate          (throughput)
//   GYROCAL_BENCH_ROWS=10000000 bench_calibrate           (the 10-million-row figure)
#include <sys/resource.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <benchmark/benchmark.h>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace {

namespace fs = std::filesystem;

/// The default scenario with enough revolutions per dwell for the requested number of rows.
gyrocal::Scenario scenario_for_rows(double rows) {
  gyrocal::Scenario s = gyrocal::default_scenario();
  const double per_dwell_s = rows / s.test.sample_rate_hz / 4.0;
  s.test.revolutions = static_cast<int>(std::max(1.0, per_dwell_s / (2 * gyrocal::kPi / 9.9)));
  return s;
}

struct RecordFile {
  gyrocal::Scenario scenario;
  fs::path path;
  double bytes = 0;
  RecordFile() {
    const char* env = std::getenv("GYROCAL_BENCH_ROWS");
    const double rows = env ? std::atof(env) : 2e6;
    scenario = scenario_for_rows(rows);
    path = fs::temp_directory_path() /
           ("gyrocal-bench-calibrate-" + std::to_string(static_cast<long>(rows)) + ".csv");
    if (!fs::exists(path)) {
      std::ofstream out(path, std::ios::binary);
      gyrocal::simulate_record(scenario, {}, out);
    }
    bytes = static_cast<double>(fs::file_size(path));
  }
};

const RecordFile& record() {
  static const RecordFile r;
  return r;
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

void BM_CalibrateRecord(benchmark::State& state) {
  const RecordFile& r = record();
  const gyrocal::CentrifugeModel model = r.scenario.model();
  gyrocal::CalibrationOptions options;
  for (auto _ : state) {
    const gyrocal::CalibrationResult result =
        gyrocal::calibrate_record(r.path.string(), model, r.scenario.test, options);
    benchmark::DoNotOptimize(result.coefficients);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(r.bytes) * state.iterations());
  state.counters["record_MB"] = r.bytes / 1e6;
  state.counters["peak_rss_MB"] = peak_rss_mb();
}
BENCHMARK(BM_CalibrateRecord)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
