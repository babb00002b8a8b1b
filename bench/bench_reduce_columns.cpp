// The reducer's cost per output column (docs/calibration.md, "Several output columns"): the same rows of a
// default-scenario record (113,000 rows at 200 Hz, held in memory so that neither reading nor simulating is
// timed) pushed through a Reducer that reduces 1, 2 or 6 output columns (an IMU's six), one accumulator each,
// on the caller's thread alone (set_threaded_accumulation(false): the work, not the overlap). Rows per
// second (items_per_second).
//   bench_reduce_columns
#include <cstdint>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace {

struct Rows {
  gyrocal::Scenario scenario;
  std::vector<gyrocal::RecordSample> rows;
  Rows() {
    scenario = gyrocal::default_scenario();
    scenario.test.revolutions = 210;
    gyrocal::simulate(scenario, {}, [&](const gyrocal::RecordSample& s) {
      gyrocal::RecordSample x = s;
      for (std::size_t k = 1; k < gyrocal::limits::kMaxOutputColumns; ++k)
        x.outputs[k] = 0.5 * static_cast<double>(k) * s.outputs[0] + static_cast<double>(k);
      rows.push_back(x);
    });
  }
};

const Rows& rows() {
  static const Rows r;
  return r;
}

void BM_ReduceColumns(benchmark::State& state) {
  const Rows& r = rows();
  const auto columns = static_cast<std::size_t>(state.range(0));
  std::vector<std::string> names;
  for (std::size_t k = 0; k < columns; ++k) names.push_back("c" + std::to_string(k));
  for (auto _ : state) {
    gyrocal::Reducer reducer(r.scenario.test, gyrocal::ReduceOptions{}, "bench",
                             r.scenario.centrifuge.rate_rad_s);
    reducer.set_threaded_accumulation(false);
    reducer.set_output_columns(names);
    for (const gyrocal::RecordSample& s : r.rows) reducer.push_unsummarised(s);
    const std::vector<gyrocal::Reduction> out = reducer.finish_channels();
    benchmark::DoNotOptimize(out.back().positions.back().mean);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(r.rows.size()) * state.iterations());  // rows per second
  state.counters["rows"] = static_cast<double>(r.rows.size());
}
BENCHMARK(BM_ReduceColumns)->Arg(1)->Arg(2)->Arg(6)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
