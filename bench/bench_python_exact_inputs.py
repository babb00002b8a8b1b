#!/usr/bin/python3
"""gyrocal.exact_inputs from Python over 1 M times against the C++ benchmark BM_ExactInputsDefaultScenario
(bench/bench_model.cpp), per evaluation; issue 10 asks for within 1.5x (docs/python.md, docs/performance.md).

    PYTHONPATH=build/python /usr/bin/python3 bench/bench_python_exact_inputs.py [--build build]

Needs a build with the benchmarks (GYROCAL_BUILD_BENCH=ON, target bench_model) and the module. Both sides evaluate
the default scenario at 9.9 rad/s, beta = 0.5 rad, at successive sample instants. Exits 1 when the ratio exceeds
1.5.
"""

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time

import numpy as np

LIMIT = 1.5


def cxx_seconds_per_evaluation(build):
    exe = os.path.join(build, "bench", "bench_model")
    out = subprocess.run([exe, "--benchmark_filter=^BM_ExactInputsDefaultScenario$", "--benchmark_format=json",
                          "--benchmark_repetitions=5", "--benchmark_report_aggregates_only=true"],
                         check=True, capture_output=True, text=True).stdout
    runs = json.loads(out)["benchmarks"]
    median = next(b for b in runs if b.get("aggregate_name") == "median")
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[median["time_unit"]]
    return median["real_time"] * scale


def python_seconds_per_evaluation(n, repeats):
    import gyrocal

    sc = gyrocal.Scenario()
    assert sc.rate_rad_s == 9.9, "the C++ benchmark runs at 9.9 rad/s, the default scenario's rate"
    times = np.arange(n, dtype=np.float64) / sc.sample_rate_hz
    beta_deg = math.degrees(0.5)
    seconds = []
    for _ in range(repeats):
        start = time.perf_counter()
        gyrocal.exact_inputs(sc, time_s=times, beta_deg=beta_deg)
        seconds.append(time.perf_counter() - start)
    return statistics.median(seconds) / n


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build", help="the build folder (default: build)")
    parser.add_argument("-n", type=int, default=1_000_000, help="times per call (default: 1 000 000)")
    parser.add_argument("--repeats", type=int, default=5, help="calls; their median counts (default: 5)")
    args = parser.parse_args()
    sys.path.insert(0, os.path.join(args.build, "python"))

    py = python_seconds_per_evaluation(args.n, args.repeats)
    cxx = cxx_seconds_per_evaluation(args.build)
    ratio = py / cxx
    print(f"C++    BM_ExactInputsDefaultScenario: {cxx * 1e9:8.1f} ns per evaluation (median of 5)")
    print(f"Python exact_inputs over {args.n} times: {py * 1e9:8.1f} ns per evaluation (median of {args.repeats})")
    print(f"ratio Python / C++: {ratio:.2f} (limit {LIMIT})")
    return 0 if ratio <= LIMIT else 1


if __name__ == "__main__":
    sys.exit(main())
