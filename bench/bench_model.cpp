// Exact-input evaluations per second on one core (issue: at least 5 million per second).
#include <benchmark/benchmark.h>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/model/centrifuge.hpp"

namespace {

void BM_ExactInputsDefaultScenario(benchmark::State& state) {
  const gyrocal::Scenario s = gyrocal::default_scenario();
  const gyrocal::CentrifugeModel model = s.model();
  double t = 0.0;
  const double dt = 1.0 / s.test.sample_rate_hz;
  for (auto _ : state) {
    const gyrocal::JointState j = gyrocal::spinning_joint_state(model, 9.9, 0.5, t);
    benchmark::DoNotOptimize(gyrocal::exact_inputs(model, j));
    t += dt;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ExactInputsDefaultScenario);

void BM_ExactInputsPerfectMachine(benchmark::State& state) {
  const gyrocal::CentrifugeModel model;
  double t = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(gyrocal::exact_inputs(model, gyrocal::spinning_joint_state(model, 9.9, 0.5, t)));
    t += 0.005;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ExactInputsPerfectMachine);

}  // namespace

BENCHMARK_MAIN();
