#pragma once
// For tests: the scenario's test simulated in memory (simulate/simulator.hpp), streamed through the reducer
// (reduce/reducer.hpp), and the model terms reduced on the same dwells (identify/model_terms.hpp): what
// `gyrocal simulate` then `gyrocal calibrate` do, without a file.
#include <cstdint>
#include <optional>
#include <vector>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/model_terms.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace gyrocal::testing {

struct Pipeline {
  Reduction reduction;
  std::vector<PositionModelTerms> model_terms;
};

/// Simulates the scenario's test with `seed` (none: the scenario's test.seed) and reduces it with `ro` on the
/// plan its sensor's record is reduced with (reduction_plan: the test itself for a gyro; an accelerometer's
/// spinning dwells at their harmonic content), as `gyrocal calibrate` reduces it.
inline Reduction simulate_and_reduce(const Scenario& s, std::optional<std::uint64_t> seed,
                                     const ReduceOptions& ro = {}) {
  Reducer reducer(reduction_plan(s.test, s.sensor_kind, ro), ro, "simulated", s.centrifuge.rate_rad_s);
  SimulationOptions so;
  so.seed = seed;
  simulate(s, so, [&](const RecordSample& sample) { reducer.push(sample); });
  return reducer.finish();
}

/// Simulates the scenario's test with `seed`, reduces it with `ro`, and reduces the exact model terms.
inline Pipeline run(const Scenario& s, std::uint64_t seed = 1, const ReduceOptions& ro = {}) {
  Pipeline p;
  p.reduction = simulate_and_reduce(s, seed, ro);
  p.model_terms = reduce_model_terms(p.reduction, s.model(), ro);
  return p;
}

}  // namespace gyrocal::testing
