// Record throughput on one core (CPU time of this process, so that a busy machine does not skew it):
// rows/s written, MB/s read, and peak memory reading a 10-million-row record.
// For a clean peak-memory figure run that benchmark alone:
//   bench_record --benchmark_filter=PeakMemory
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "gyrocal/core/atomic_file.hpp"
#include "gyrocal/record/record.hpp"

namespace {

namespace fs = std::filesystem;
using gyrocal::RecordSample;

/// Sample i of a plausible record: 200 Hz, the main axis at 9.9 rad/s unwrapped, the counter platform
/// opposite, a gyro output with noise (full 17-digit numbers, as a simulation writes them).
class SampleSource {
 public:
  SampleSource() {
    std::mt19937_64 random(1);
    std::normal_distribution<double> noise(0.0, 0.1);
    for (double& value : noise_) value = noise(random);
  }
  RecordSample operator()(std::uint64_t i) const {
    RecordSample sample;
    sample.time_s = static_cast<double>(i) * 0.005;
    sample.main_angle_deg = sample.time_s * 567.2282172309;
    sample.counter_angle_deg = -sample.main_angle_deg;
    sample.position_angle_deg = 90.0;
    sample.outputs[0] = 1.2345 + noise_[i % noise_.size()];
    sample.extra[0] = 21.0 + noise_[(i + 7) % noise_.size()];
    return sample;
  }

 private:
  std::array<double, 4096> noise_{};
};

fs::path temporary_path(const std::string& name) {
  return fs::temp_directory_path() / ("gyrocal_bench_" + std::to_string(::getpid()) + "_" + name + ".csv");
}

void write_record(const fs::path& path, std::uint64_t rows) {
  const SampleSource source;
  gyrocal::AtomicOutputFile file(path, true);
  gyrocal::RecordWriter writer(file.stream(), {{"source", "bench_record"}}, {"temperature_c"});
  for (std::uint64_t i = 0; i < rows; ++i) writer.write(source(i));
  writer.finish();
  file.commit();
}

/// Removes the benchmark's files at exit.
struct TemporaryFiles {
  ~TemporaryFiles() {
    for (const char* name : {"write", "read", "peak"}) fs::remove(temporary_path(name));
  }
} temporary_files;

/// Resident memory now, MB (from /proc/self/statm).
double resident_mb() {
  std::ifstream statm("/proc/self/statm");
  long pages_total = 0;
  long pages_resident = 0;
  statm >> pages_total >> pages_resident;
  return static_cast<double>(pages_resident) * static_cast<double>(::sysconf(_SC_PAGESIZE)) / 1048576.0;
}

/// Peak resident memory of the process so far, MB.
double peak_resident_mb() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

void BM_WriteRecord(benchmark::State& state) {
  const auto rows = static_cast<std::uint64_t>(state.range(0));
  const fs::path path = temporary_path("write");
  for (auto _ : state) write_record(path, rows);
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(fs::file_size(path)));
  state.counters["file_MB"] = static_cast<double>(fs::file_size(path)) / 1e6;
}
BENCHMARK(BM_WriteRecord)->Arg(2'000'000)->Unit(benchmark::kMillisecond);

void BM_ReadRecord(benchmark::State& state) {
  const auto rows = static_cast<std::uint64_t>(state.range(0));
  const fs::path path = temporary_path("read");
  if (!fs::exists(path)) write_record(path, rows);
  for (auto _ : state) {
    gyrocal::RecordReader reader(path);
    RecordSample sample;
    double sum = 0.0;
    while (reader.next(sample)) sum += sample.outputs[0];
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(fs::file_size(path)));
}
BENCHMARK(BM_ReadRecord)->Arg(4'000'000)->Unit(benchmark::kMillisecond);

/// Reads a 10-million-row record, sampling resident memory every million rows: peak_MB is the
/// process's peak, growth_MB the largest rise of resident memory above its level before reading.
void BM_ReadRecordPeakMemory(benchmark::State& state) {
  const auto rows = static_cast<std::uint64_t>(state.range(0));
  const fs::path path = temporary_path("peak");
  if (!fs::exists(path)) write_record(path, rows);
  double growth_mb = 0.0;
  for (auto _ : state) {
    const double before_mb = resident_mb();
    gyrocal::RecordReader reader(path);
    RecordSample sample;
    std::uint64_t count = 0;
    while (reader.next(sample)) {
      if (++count % 1'000'000 == 0) growth_mb = std::max(growth_mb, resident_mb() - before_mb);
    }
    benchmark::DoNotOptimize(count);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(fs::file_size(path)));
  state.counters["file_MB"] = static_cast<double>(fs::file_size(path)) / 1e6;
  state.counters["peak_MB"] = peak_resident_mb();
  state.counters["growth_MB"] = growth_mb;
}
BENCHMARK(BM_ReadRecordPeakMemory)->Arg(10'000'000)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
