#!/usr/bin/python3
"""`gyrocal calibrate` of a whole IMU's record beside pandas.read_csv of the same file, same machine, same run
(issue 27, item 5; docs/performance.md, "A whole IMU").

    bench/bench_imu_vs_pandas.py BUILD_DIR [--rows 2000000] [--rounds 5] [--keep DIR]

Writes the default IMU (`gyrocal init --sensor imu`: six channels gx gy gz ax ay az written as increments, the
accelerometer's plan of static holds and two rates at four beta, the radius error and its stretch estimated)
with its sample rate raised so that the record has about ROWS rows (the rows grow with the sample rate: the
plan's durations stay), and simulates it once. Then, in ROUNDS interleaved rounds: pandas.read_csv of the
record, `gyrocal calibrate` of it end to end (the wall time of the process, start to exit; its default two
threads) and the same on one core (`taskset -c 0`). Prints the medians, the ratios pandas / calibrate per round
(target >= 2) and calibrate's peak memory (target < 64 MB).
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

from bench_read_vs_pandas import calibrate, pandas_read

# `gyrocal init --sensor imu`'s sample rate and the rows its record then has (docs/imu.md, "The default IMU").
DEFAULT_RATE_HZ = 200.0
DEFAULT_ROWS = 249964


def imu_scenario(gyrocal, folder, rows):
    """The default IMU with its sample rate set for about `rows` rows."""
    path = os.path.join(folder, "imu.toml")
    subprocess.run([gyrocal, "init", "--sensor", "imu", "--force", path], check=True, capture_output=True)
    with open(path) as f:
        text = f.read()
    rate = DEFAULT_RATE_HZ * rows / DEFAULT_ROWS
    text, count = re.subn(r"(?m)^sample_rate_hz = [0-9.]+", f"sample_rate_hz = {rate:.6f}", text)
    assert count == 1, "gyrocal init --sensor imu wrote no [test] sample_rate_hz"
    with open(path, "w") as f:
        f.write(text)
    return path


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build", help="the build folder (holds gyrocal)")
    parser.add_argument("--rows", type=float, default=2e6)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--keep", help="folder for the record (default: a temporary one, removed)")
    args = parser.parse_args()
    gyrocal = os.path.join(args.build, "gyrocal")
    with tempfile.TemporaryDirectory(prefix="gyrocal-bench-imu-") as temporary:
        folder = args.keep or temporary
        os.makedirs(folder, exist_ok=True)
        scenario = imu_scenario(gyrocal, folder, args.rows)
        record = os.path.join(folder, "imu.csv")
        if not os.path.exists(record):
            subprocess.run([gyrocal, "simulate", "--config", scenario, "--out", record], check=True,
                           capture_output=True)
        start_load = os.getloadavg()
        pandas_s, calibrate_s, one_core_s, peak = [], [], [], 0.0
        for _ in range(args.rounds):
            pandas_s.append(pandas_read(record))
            seconds, mb = calibrate(gyrocal, record, scenario, folder)
            calibrate_s.append(seconds)
            peak = max(peak, mb)
            seconds, mb = calibrate(gyrocal, record, scenario, folder, one_core=True)
            one_core_s.append(seconds)
            peak = max(peak, mb)
        rows = sum(1 for line in open(record) if not line.startswith("#")) - 1
        med = statistics.median
        print(f"IMU record: {rows} rows, 6 channels (increments), {os.path.getsize(record) / 1e6:.1f} MB; "
              f"{args.rounds} rounds, medians (min-max)")
        for name, values in (("pandas.read_csv", pandas_s), ("gyrocal calibrate", calibrate_s),
                             ("gyrocal calibrate, one core", one_core_s)):
            print(f"  {name:30s} {med(values):7.3f} s  ({min(values):.3f}-{max(values):.3f})")
        for name, values in (("calibrate", calibrate_s), ("calibrate on one core", one_core_s)):
            ratios = [p / c for p, c in zip(pandas_s, values)]
            print(f"pandas / gyrocal {name}: {med(pandas_s) / med(values):.2f}x (per round {min(ratios):.2f}-"
                  f"{max(ratios):.2f}; target >= 2)")
        print(f"gyrocal calibrate peak memory: {peak:.1f} MB (target < 64)")
        print(f"load average at the start {' '.join(f'{x:.1f}' for x in start_load)}, at the end: "
              f"{' '.join(f'{x:.1f}' for x in os.getloadavg())} on {os.cpu_count()} cores")


if __name__ == "__main__":
    sys.exit(main())
