"""An accelerometer from Python (issue 19; docs/python.md): its record keyed by its own column, its noise keyed as
[accelerometer.noise] equal to the command line's, and the other sensor's record refused with the command line's
sentence.

ctest runs this file as test_gyrocal.py is run (tests/CMakeLists.txt): PYTHONPATH=<build>/python and GYROCAL_CLI
set to the command line's executable.
"""

import json
import os
import subprocess

import numpy as np
import pytest

import gyrocal

CLI = os.environ.get("GYROCAL_CLI", "gyrocal")

ACCELEROMETER = '[sensor]\nkind = "accelerometer"\n'
# A short accelerometer test: one speed, four beta, eight gamma, 100 Hz.
SHORT = ACCELEROMETER + """
[test]
sample_rate_hz = 100.0
revolutions = 3
settle_s = 1.0
rates_rad_s = [6.0]
gamma_deg = [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0]
"""


def run_cli(*args, check=True):
    proc = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    if check:
        assert proc.returncode == 0, proc.stderr
    return proc


def test_simulate_keys_the_output_by_the_sensors_own_column(tmp_path):
    sc = gyrocal.Scenario.parse(SHORT)
    assert sc.sensor_kind == "accelerometer"
    assert sc.output_column == "accel_g"
    assert gyrocal.Scenario().output_column == "gyro_deg_h"
    rec = gyrocal.simulate(sc, seed=2)
    assert list(rec) == ["time_s", "main_angle_deg", "counter_angle_deg", "position_angle_deg", "accel_g"]
    # The command line's record, bit for bit.
    config, record = tmp_path / "a.toml", tmp_path / "a.csv"
    config.write_text(SHORT)
    run_cli("simulate", "--config", config, "--out", record, "--seed", 2)
    lines = [line for line in record.read_text().splitlines() if not line.startswith("#")]
    assert lines[0].split(",")[-1] == "accel_g"
    output = np.array([float(line.split(",")[4]) for line in lines[1:]])
    assert np.array_equal(output, rec["accel_g"])


def test_the_other_sensors_record_is_refused_naming_the_column(tmp_path):
    accel = gyrocal.Scenario.parse(SHORT)
    rec = gyrocal.simulate(accel, seed=2)
    with pytest.raises(ValueError, match="its output column is accel_g.*the gyro"):
        gyrocal.calibrate(rec, gyrocal.Scenario())
    gyro_rec = {"time_s": rec["time_s"], "main_angle_deg": rec["main_angle_deg"],
                "counter_angle_deg": rec["counter_angle_deg"],
                "position_angle_deg": rec["position_angle_deg"], "gyro_deg_h": rec["accel_g"]}
    with pytest.raises(ValueError, match="its output column is gyro_deg_h.*an accelerometer"):
        gyrocal.calibrate(gyro_rec, accel)
    # From a path, with the command line's sentence.
    config, record = tmp_path / "a.toml", tmp_path / "a.csv"
    config.write_text(SHORT)
    run_cli("simulate", "--config", config, "--out", record)
    proc = run_cli("calibrate", record, check=False)
    assert proc.returncode == 1
    sentence = proc.stderr[len("gyrocal: "):].rstrip("\n")
    with pytest.raises(ValueError) as error:
        gyrocal.calibrate(str(record), gyrocal.Scenario())
    assert str(error.value) == sentence.replace("the built-in scenario", "the scenario")


def test_noise_of_an_accelerometer_equals_the_command_lines(tmp_path):
    rng = np.random.default_rng(5)
    fs, n = 50.0, 20000
    t = np.arange(n) / fs
    # 20 ug/sqrt(Hz) of white noise on 1 g: one sample's sigma is 20 sqrt(fs) ug.
    g = 1.0 + 20e-6 * np.sqrt(fs) * rng.standard_normal(n)
    record = tmp_path / "static.csv"
    with open(record, "w") as out:
        out.write("# gyrocal-record 1\ntime_s,accel_g\n")
        for ti, gi in zip(t, g):
            out.write(f"{ti!r},{gi!r}\n")
    cli = json.loads(run_cli("noise", record, "--json", "-").stdout)
    from_path = gyrocal.noise(str(record))
    from_arrays = gyrocal.noise({"time_s": t, "accel_g": g})
    for result in (from_path, from_arrays):
        assert result["sensor"] == "accelerometer"
        assert result["unit"] == "ug"
        assert [p["adev"] for p in result["allan"]] == [p["adev"] for p in cli["allan"]]
        assert result["terms"] == cli["terms"]
    n_fit = cli["terms"]["velocity_random_walk_ug_rt_hz"]
    assert abs(n_fit["value"] - 20.0) < 3 * n_fit["std"]
    # With the accelerometer's scenario likewise; with the gyro's, refused by name.
    assert gyrocal.noise(str(record), gyrocal.Scenario.parse(ACCELEROMETER))["terms"] == cli["terms"]
    with pytest.raises(ValueError, match="its output column is accel_g"):
        gyrocal.noise(str(record), gyrocal.Scenario())
