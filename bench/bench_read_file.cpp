// Reads one record file through the streaming reader and nothing else, for side-by-side timings against other
// readers (bench/bench_read_vs_pandas.py; docs/performance.md):
//   bench_read_file RECORD [CONFIG.toml]
// CONFIG's [record] section, when given, is the record's layout (docs/records.md). Prints one line:
//   rows=N seconds=S mb_per_s=M peak_rss_mb=P
// with S the wall time of opening and reading every row (steady clock), and P the process's peak resident
// memory (VmHWM: this program's own, whereas ru_maxrss would carry over the launching process's peak).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/record/record.hpp"

/// The peak resident memory of this process, MB (VmHWM of /proc/self/status).
double peak_resident_mb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
  }
  return 0.0;
}

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: bench_read_file RECORD [CONFIG.toml]\n");
    return 2;
  }
  try {
    std::optional<gyrocal::RecordLayout> layout;
    if (argc == 3) layout = gyrocal::load_scenario(argv[2]).record;
    const auto start = std::chrono::steady_clock::now();
    gyrocal::RecordReader reader(argv[1], layout);
    gyrocal::RecordSample sample;
    std::uint64_t rows = 0;
    double sum = 0.0;  // every value used, so that nothing is optimised away
    while (reader.next(sample)) {
      ++rows;
      sum += sample.time_s + sample.main_angle_deg + sample.counter_angle_deg + sample.position_angle_deg +
             sample.outputs[0];
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double bytes = static_cast<double>(std::filesystem::file_size(argv[1]));
    std::printf("rows=%llu seconds=%.6f mb_per_s=%.1f peak_rss_mb=%.1f checksum=%.6g\n",
                static_cast<unsigned long long>(rows), seconds, bytes / seconds / 1e6, peak_resident_mb(),
                sum);
  } catch (const gyrocal::Error& e) {
    std::fprintf(stderr, "bench_read_file: %s\n", e.what());
    return 1;
  }
  return 0;
}
