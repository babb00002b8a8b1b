#!/usr/bin/python3
"""gyrocal's record reader and `gyrocal calibrate` beside pandas.read_csv on the same record, same machine, same
run (issue 8, "Speed and memory"; issue 17, item 1; docs/performance.md).

    bench/bench_read_vs_pandas.py BUILD_DIR [--rows 2000000] [--rounds 5] [--keep DIR] [--no-calibrate]
                                  [--sensor gyro|both]

Writes a simulated record of about ROWS rows once (`gyrocal simulate`), and the same samples as a rig would
write them: ';' between fields, time stamps in integer ms, the three angles as encoder counts (2^24 a
revolution, the main axis wrapped), the output in mV at 2.5 mV per deg/h, read through a [record] mapping.
Then, in ROUNDS interleaved rounds: the gyrocal reader on the native record (bench_read_file, the reader
alone), pandas.read_csv on the native record, the gyrocal reader on the foreign record, `gyrocal calibrate` of
the native record end to end (default reduction and compensation; the wall time of the process, start to
exit) and the same on one core (`taskset -c 0`: its threads share one CPU). Prints the medians, the ratios
pandas / gyrocal reader (target >= 3), pandas / calibrate (target >= 3), foreign / native (target <= 1.5), and
the peak memory of the reader and of calibrate (target < 64 MB).

With --sensor both (issue 17, item 2; issue 19), each round also reads and calibrates an accelerometer's record
of the same number of rows at the same sample rate: the default accelerometer scenario (`gyrocal init --sensor
accelerometer`: static holds, 6 and 12 rad/s, four beta) with its revolutions set so that the record has about
ROWS rows. Prints its calibration's medians (two threads, one core), the ratio accelerometer / gyro per round
(target <= 1.5), pandas.read_csv of its own record / its calibration, and its peak memory.
"""
import argparse
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

import pandas as pd

COUNTS = 1 << 24
MV_PER_DEG_H = 2.5
FOREIGN_TOML = """[record]
delimiter = ";"
time_column = "t_ms"
time_unit = "ms"
main_angle_column = "theta_cnt"
counter_angle_column = "psi_cnt"
position_angle_column = "beta_cnt"
main_counts_per_revolution = 16777216
counter_counts_per_revolution = 16777216
position_counts_per_revolution = 16777216
output_column = "U_mV"
output_scale_per_deg_h = 2.5
"""


def gyrocal_read(bench, record, config=None):
    args = [bench, record] + ([config] if config else [])
    out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    return {k: float(v) for k, v in re.findall(r"(\w+)=([-0-9.e+]+)", out)}


def timed_process(args):
    """Runs args; returns (wall seconds, peak resident memory in MB) of that process alone. The memory is
    /usr/bin/time's: the peak of a child forked from this Python (pandas loaded) would count the Python's pages
    too."""
    start = time.perf_counter()
    done = subprocess.run(["/usr/bin/time", "-f", "maxrss_kb=%M"] + args, stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        raise RuntimeError(f"{args[0]} failed: {done.stderr}")
    return seconds, float(re.findall(r"maxrss_kb=(\d+)", done.stderr)[-1]) / 1024.0


def calibrate(gyrocal, record, scenario, folder, one_core=False):
    result = os.path.join(folder, "result.json")
    if os.path.exists(result):
        os.remove(result)
    args = [gyrocal, "calibrate", record, "--config", scenario, "--json", result]
    return timed_process((["taskset", "-c", "0"] if one_core else []) + args)


def pandas_read(record):
    start = time.perf_counter()
    frame = pd.read_csv(record, comment="#")
    seconds = time.perf_counter() - start
    assert len(frame) > 0
    return seconds


def write_foreign(native, foreign):
    frame = pd.read_csv(native, comment="#")
    out = pd.DataFrame({
        "t_ms": (frame["time_s"] * 1000.0).round().astype("int64"),
        "theta_cnt": (frame["main_angle_deg"] / 360.0 * COUNTS).round().astype("int64") % COUNTS,
        "psi_cnt": (frame["counter_angle_deg"] / 360.0 * COUNTS).round().astype("int64"),
        "beta_cnt": (frame["position_angle_deg"] / 360.0 * COUNTS).round().astype("int64"),
        "U_mV": frame["gyro_deg_h"] * MV_PER_DEG_H,
    })
    out.to_csv(foreign, sep=";", index=False, float_format="%.17g")


def accelerometer_scenario(gyrocal, folder, rows):
    """The default accelerometer scenario with its revolutions set for about `rows` rows: the rows grow
    linearly with the revolutions (static holds and settles fixed), so two short simulations give the line."""
    base = os.path.join(folder, "accelerometer-default.toml")
    subprocess.run([gyrocal, "init", "--sensor", "accelerometer", "--force", base], check=True,
                   capture_output=True)
    with open(base) as f:
        text = f.read()

    def with_revolutions(n):
        out, count = re.subn(r"(?m)^revolutions = \d+", f"revolutions = {n}", text)
        assert count == 1, "gyrocal init --sensor accelerometer wrote no [test] revolutions"
        return out

    def samples(n):
        path = os.path.join(folder, f"accelerometer-{n}.toml")
        with open(path, "w") as f:
            f.write(with_revolutions(n))
        out = subprocess.run([gyrocal, "simulate", "--config", path, "--out", os.devnull], check=True,
                             capture_output=True, text=True).stdout
        os.remove(path)
        return int(re.search(r"(\d+) samples", out).group(1))

    at_10, at_20 = samples(10), samples(20)
    per_revolution = (at_20 - at_10) / 10.0
    revolutions = max(3, round(10 + (rows - at_10) / per_revolution))
    scenario = os.path.join(folder, "accelerometer.toml")
    with open(scenario, "w") as f:
        f.write(with_revolutions(revolutions))
    return scenario


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build", help="the build folder (holds gyrocal and bench/bench_read_file)")
    parser.add_argument("--rows", type=float, default=2e6)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--keep", help="folder for the records (default: a temporary one, removed)")
    parser.add_argument("--no-calibrate", action="store_true", help="time the readers only")
    parser.add_argument("--sensor", choices=["gyro", "both"], default="gyro",
                        help="both: also an accelerometer's record of the same rows, read and calibrated")
    args = parser.parse_args()
    gyrocal = os.path.join(args.build, "gyrocal")
    bench = os.path.join(args.build, "bench", "bench_read_file")
    with tempfile.TemporaryDirectory(prefix="gyrocal-bench-read-") as temporary:
        folder = args.keep or temporary
        os.makedirs(folder, exist_ok=True)
        native = os.path.join(folder, "native.csv")
        foreign = os.path.join(folder, "foreign.csv")
        config = os.path.join(folder, "foreign.toml")
        # The default 16-position test at 200 Hz: 4 dwells of revolutions * 2 pi / 9.9 s.
        revolutions = max(1, int(args.rows / 200.0 / 4.0 / (2 * math.pi / 9.9)))
        scenario = os.path.join(folder, "scenario.toml")
        with open(scenario, "w") as f:
            f.write(f"[test]\nrevolutions = {revolutions}\n")
        if not os.path.exists(native):
            subprocess.run([gyrocal, "simulate", "--config", scenario, "--out", native], check=True,
                           capture_output=True)
        if not os.path.exists(foreign):
            write_foreign(native, foreign)
        with open(config, "w") as f:
            f.write(FOREIGN_TOML)
        both = args.sensor == "both" and not args.no_calibrate
        if both:
            accel = os.path.join(folder, "accelerometer.csv")
            accel_scenario = accelerometer_scenario(gyrocal, folder, args.rows)
            if not os.path.exists(accel):
                subprocess.run([gyrocal, "simulate", "--config", accel_scenario, "--out", accel], check=True,
                               capture_output=True)
        accel_pandas_s, accel_s, accel_one_s, accel_peak = [], [], [], 0.0
        start_load = os.getloadavg()
        native_s, pandas_s, foreign_s, calibrate_s, one_core_s, peak, calibrate_peak = [], [], [], [], [], 0.0, 0.0
        for _ in range(args.rounds):
            n = gyrocal_read(bench, native)
            native_s.append(n["seconds"])
            pandas_s.append(pandas_read(native))
            f = gyrocal_read(bench, foreign, config)
            foreign_s.append(f["seconds"])
            peak = max(peak, n["peak_rss_mb"], f["peak_rss_mb"])
            assert n["rows"] == f["rows"], (n, f)
            if not args.no_calibrate:
                seconds, mb = calibrate(gyrocal, native, scenario, folder)
                calibrate_s.append(seconds)
                calibrate_peak = max(calibrate_peak, mb)
                seconds, mb = calibrate(gyrocal, native, scenario, folder, one_core=True)
                one_core_s.append(seconds)
                calibrate_peak = max(calibrate_peak, mb)
            if both:
                accel_pandas_s.append(pandas_read(accel))
                seconds, mb = calibrate(gyrocal, accel, accel_scenario, folder)
                accel_s.append(seconds)
                accel_peak = max(accel_peak, mb)
                seconds, mb = calibrate(gyrocal, accel, accel_scenario, folder, one_core=True)
                accel_one_s.append(seconds)
                accel_peak = max(accel_peak, mb)
        mb = os.path.getsize(native) / 1e6
        med = statistics.median
        print(f"record: {int(n['rows'])} rows, native {mb:.1f} MB, foreign {os.path.getsize(foreign) / 1e6:.1f} MB;"
              f" {args.rounds} rounds, medians (min-max)")
        rows = [("gyrocal reader, native", native_s), ("pandas.read_csv, native", pandas_s),
                ("gyrocal reader, foreign (mapped)", foreign_s)]
        if calibrate_s:
            rows += [("gyrocal calibrate, native", calibrate_s), ("gyrocal calibrate, one core", one_core_s)]
        for name, values in rows:
            print(f"  {name:34s} {med(values):7.3f} s  ({min(values):.3f}-{max(values):.3f})")
        ratios = [p / g for p, g in zip(pandas_s, native_s)]
        print(f"pandas / gyrocal native: {med(pandas_s) / med(native_s):.2f}x (per round {min(ratios):.2f}-"
              f"{max(ratios):.2f}; target >= 3)")
        print(f"foreign / native: {med(foreign_s) / med(native_s):.2f}x (target <= 1.5)")
        print(f"gyrocal reader peak memory: {peak:.1f} MB")
        if calibrate_s:
            for name, values in (("calibrate", calibrate_s), ("calibrate on one core", one_core_s)):
                ratios = [p / c for p, c in zip(pandas_s, values)]
                print(f"pandas / gyrocal {name}: {med(pandas_s) / med(values):.2f}x (per round {min(ratios):.2f}-"
                      f"{max(ratios):.2f}; target >= 3)")
            print(f"gyrocal calibrate peak memory: {calibrate_peak:.1f} MB (target < 64)")
        if accel_s:
            rows_accel = sum(1 for line in open(accel) if not line.startswith("#")) - 1
            print(f"accelerometer record: {rows_accel} rows, {os.path.getsize(accel) / 1e6:.1f} MB, the same "
                  "sample rate")
            for name, values in (("pandas.read_csv, accelerometer", accel_pandas_s),
                                 ("calibrate accelerometer", accel_s), ("calibrate accelerometer, one core",
                                                                        accel_one_s)):
                print(f"  {name:34s} {med(values):7.3f} s  ({min(values):.3f}-{max(values):.3f})")
            for name, a_values, g_values in (("two threads", accel_s, calibrate_s),
                                             ("one core", accel_one_s, one_core_s)):
                ratios = [a / g for a, g in zip(a_values, g_values)]
                print(f"accelerometer / gyro calibrate, {name}: {med(a_values) / med(g_values):.2f}x (per round "
                      f"{min(ratios):.2f}-{max(ratios):.2f}; target <= 1.5)")
            for name, values in (("calibrate", accel_s), ("calibrate on one core", accel_one_s)):
                ratios = [p / c for p, c in zip(accel_pandas_s, values)]
                print(f"pandas (accelerometer record) / accelerometer {name}: "
                      f"{med(accel_pandas_s) / med(values):.2f}x (per round {min(ratios):.2f}-{max(ratios):.2f})")
            print(f"accelerometer calibrate peak memory: {accel_peak:.1f} MB (target < 64)")
        if calibrate_s:
            print(f"load average at the start {' '.join(f'{x:.1f}' for x in start_load)}, at the end: "
                  f"{' '.join(f'{x:.1f}' for x in os.getloadavg())} on {os.cpu_count()} cores")


if __name__ == "__main__":
    sys.exit(main())
