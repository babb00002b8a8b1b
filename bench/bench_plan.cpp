// `gyrocal plan` of the default scenario at 200 .. 2,000,000 revolutions per dwell (issue 17, item 3: a cost
// independent of the revolutions, a 2e6-revolution plan under 1 s). The model's channels of each planned
// dwell are summed in closed form (identify/planned_channels.hpp), so the time should stay flat.
#include <benchmark/benchmark.h>

#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/config/scenario.hpp"

namespace gyrocal {
namespace {

void BM_Plan(benchmark::State& state) {
  Scenario s = default_scenario();
  s.test.revolutions = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(predict_calibration(s, CalibrationOptions{}));
  state.SetLabel("default scenario, 16 positions, white noise");
}
BENCHMARK(BM_Plan)->Arg(200)->Arg(20000)->Arg(2000000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace gyrocal

BENCHMARK_MAIN();
