// `gyrocal plan` of the default scenario at 200 .. 2,000,000 revolutions per dwell (issue 17, item 3: a cost
// independent of the revolutions, a 2e6-revolution plan under 1 s). The model terms of each planned
// dwell are summed in closed form (identify/planned_model_terms.hpp), and so is the coloured noise's
// covariance (analysis/predict.hpp, coloured_noise_position_covariance), so the time should stay flat.
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

void BM_PlanColoured(benchmark::State& state) {
  Scenario s = default_scenario();
  s.test.revolutions = static_cast<int>(state.range(0));
  s.noise.bias_instability_deg_h = 0.05;
  s.noise.rate_random_walk_deg_h_rt_h = 0.5;
  s.noise.quantization_deg_h = 0.01;
  s.noise.output_lag_s = 0.001;
  for (auto _ : state) benchmark::DoNotOptimize(predict_calibration(s, CalibrationOptions{}));
  state.SetLabel("default scenario, 16 positions, B 0.05, K 0.5, q 0.01, lag 1 ms");
}
BENCHMARK(BM_PlanColoured)
    ->Arg(200)
    ->Arg(2000)
    ->Arg(20000)
    ->Arg(2000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace gyrocal

BENCHMARK_MAIN();
