"""A whole IMU from Python (issue 27; docs/python.md, "An IMU"): simulate gives the command line's record (every
channel's column, in its own units), and calibrate and noise of an IMU's scenario give the command line's JSON,
from the record's file or from a mapping of its columns; a mapping that lacks a channel's column is refused naming
it.

ctest runs this file as test_gyrocal.py is run (tests/CMakeLists.txt): PYTHONPATH=<build>/python and GYROCAL_CLI
set to the command line's executable.
"""

import json
import os
import re
import subprocess

import numpy as np
import pytest

import gyrocal

CLI = os.environ.get("GYROCAL_CLI", "gyrocal")

CHANNELS = ("gx", "gy", "gz", "ax", "ay", "az")


def run_cli(*args, check=True):
    proc = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    if check:
        assert proc.returncode == 0, proc.stderr
    return proc


def cli_result(path):
    """A result file as Python returns it: without what only a file carries (docs/interface.md)."""
    result = json.loads(path.read_text())
    for key in ("gyrocal", "config", "plan"):
        result.pop(key, None)
    return result


def read_columns(path):
    """The record's columns as written (float() is exact for the writer's shortest form)."""
    with open(path) as f:
        lines = [line.rstrip("\n") for line in f if not line.startswith("#")]
    header = lines[0].split(",")
    data = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    return header, {name: data[:, i].copy() for i, name in enumerate(header)}


@pytest.fixture(scope="module")
def short_imu(tmp_path_factory):
    """The default IMU (init --sensor imu) on a short test, as tests/test_imu_cli.cpp shortens it: 6 revolutions,
    static holds of 2 s, 50 Hz; its configuration, its record (simulate --seed 3) and the command line's
    calibration of it."""
    folder = tmp_path_factory.mktemp("imu")
    config = folder / "imu.toml"
    run_cli("init", "--sensor", "imu", config)
    text = config.read_text()
    text = re.sub(r"revolutions = 100\b", "revolutions = 6", text)
    text = re.sub(r"static_hold_s = 10\.0", "static_hold_s = 2.0", text)
    text = re.sub(r"sample_rate_hz = 200\.0", "sample_rate_hz = 50.0", text)
    config.write_text(text)
    record, result = folder / "imu.csv", folder / "imu.json"
    run_cli("simulate", "--config", config, "--out", record, "--seed", 3)
    run_cli("calibrate", record, "--config", config, "--json", result)
    return gyrocal.Scenario.load(str(config)), record, cli_result(result)


def test_imu_columns_are_the_records_header(short_imu):
    sc, record, _ = short_imu
    header, _ = read_columns(record)
    assert gyrocal.imu_columns(sc) == tuple(header)
    assert gyrocal.imu_columns(sc, angles=False) == ("time_s",) + CHANNELS
    with pytest.raises(ValueError, match="not an IMU's"):
        gyrocal.imu_columns(gyrocal.Scenario())


def test_calibrate_from_path_and_mapping_equal_the_command_line(short_imu):
    sc, record, expected = short_imu
    assert expected["sensor"] == "imu"
    assert list(expected["channels"]) == list(CHANNELS)
    assert gyrocal.calibrate(str(record), sc) == expected
    # The mapping holds the file's columns as written (increments in rad and m/s), plus one it ignores.
    _, columns = read_columns(record)
    columns["temperature_c"] = np.full(len(columns["time_s"]), 21.0)
    from_mapping = gyrocal.calibrate(columns, sc)
    assert from_mapping.pop("record") == "<arrays>"
    expected = dict(expected)
    expected.pop("record")
    assert from_mapping == expected


def test_simulate_gives_the_command_lines_record_which_calibrates_as_its_file(short_imu):
    sc, record, expected = short_imu
    header, written = read_columns(record)
    simulated = gyrocal.simulate(sc, seed=3)
    assert list(simulated) == header
    for name in header:
        assert simulated[name].tobytes() == written[name].tobytes(), name  # bit for bit
    result = gyrocal.calibrate(simulated, sc)
    assert result.pop("record") == "<arrays>"
    expected = dict(expected)
    expected.pop("record")
    assert result == expected


def test_calibrate_refuses_a_mapping_without_a_channels_column(short_imu):
    sc, record, _ = short_imu
    _, columns = read_columns(record)
    del columns["ay"]
    with pytest.raises(ValueError, match=r"^<arrays>: the record has no column ay\.$"):
        gyrocal.calibrate(columns, sc)


def short_imu_config(record):
    return record.parent / "imu.toml"


def test_calibrate_refuses_what_an_imu_does_not_take(short_imu):
    sc, record, _ = short_imu
    # The command line's sentence, from the same library function.
    cli = run_cli("calibrate", record, "--config", short_imu_config(record), "--method", "closed-form",
                  check=False)
    assert cli.returncode == 1
    with pytest.raises(ValueError) as refusal:
        gyrocal.calibrate(str(record), sc, method="closed-form")
    assert cli.stderr == f"gyrocal: {refusal.value}\n"


def write_static_imu(path, rng, n, fs, truth):
    """A static record of the output alone: gx (deg/h, white noise and a rate random walk), gz (an angle
    increment, rad), ax (m/s^2), az (a velocity increment, m/s, with gravity), from white noise of density N
    (deg/sqrt(h), 60 deg/h/sqrt(Hz); ug/sqrt(Hz)): a sample's std is N sqrt(fs)."""
    t = np.arange(n) / fs
    dt = np.diff(t, prepend=t[0] - 1.0 / fs)  # what the reader divides an increment by
    root = np.sqrt(fs)
    walk = np.concatenate(([0.0], np.cumsum(truth["gx_K"] / 60.0 * np.sqrt(1.0 / fs) * rng.normal(size=n - 1))))
    gx = 9.5 + walk + truth["gx"] * 60.0 * root * rng.normal(size=n)
    gz = (-3.0 + truth["gz"] * 60.0 * root * rng.normal(size=n)) * 4.84813681109536e-6 * dt
    ax = (1e-3 + truth["ax"] * 1e-6 * root * rng.normal(size=n)) * 9.80665
    az = (1.0 + truth["az"] * 1e-6 * root * rng.normal(size=n)) * 9.80665 * dt
    columns = {"time_s": t, "gx": gx, "gz": gz, "ax": ax, "az": az}
    with open(path, "w") as f:
        f.write(",".join(columns) + "\n")
        for row in zip(*columns.values()):
            f.write(",".join(repr(float(v)) for v in row) + "\n")
    return columns


STATIC_IMU = """[sensor]
kind = "imu"

[[channel]]
name = "gx"
sensor = "gyro"
input_axis = "+x"
second_axis = "+y"

[[channel]]
name = "gz"
sensor = "gyro"
input_axis = "+z"
second_axis = "+x"
output = "increment"
output_scale = 4.84813681109536e-6

[[channel]]
name = "ax"
sensor = "accelerometer"
input_axis = "+x"
second_axis = "+y"
output_scale = 9.80665

[[channel]]
name = "az"
sensor = "accelerometer"
input_axis = "+z"
second_axis = "+x"
output = "increment"
output_scale = 9.80665
"""


def test_noise_of_every_channel_equals_the_command_line_and_recovers_the_truth(tmp_path):
    truth = {"gx": 0.05, "gx_K": 100.0, "gz": 0.02, "ax": 20.0, "az": 50.0}
    config, record, result = tmp_path / "imu.toml", tmp_path / "static.csv", tmp_path / "noise.json"
    config.write_text(STATIC_IMU)
    columns = write_static_imu(record, np.random.default_rng(11), 40000, 20.0, truth)
    run_cli("noise", record, "--config", config, "--json", result)
    expected = cli_result(result)
    sc = gyrocal.Scenario.load(str(config))
    assert gyrocal.noise(str(record), sc) == expected
    from_mapping = gyrocal.noise(columns, sc)
    assert from_mapping.pop("record") == "<arrays>"
    expected.pop("record")
    assert from_mapping == expected

    channels = expected["channels"]
    assert list(channels) == ["gx", "gz", "ax", "az"]
    assert [channels[c]["unit"] for c in channels] == ["deg/h", "deg/h", "ug", "ug"]
    recovered = {
        "gx": channels["gx"]["terms"]["angle_random_walk_deg_rt_h"],
        "gx_K": channels["gx"]["terms"]["rate_random_walk_deg_h_rt_h"],
        "gz": channels["gz"]["terms"]["angle_random_walk_deg_rt_h"],
        "ax": channels["ax"]["terms"]["velocity_random_walk_ug_rt_hz"],
        "az": channels["az"]["terms"]["velocity_random_walk_ug_rt_hz"],
    }
    for key, term in recovered.items():
        # Within 3 stated standard uncertainties (docs/noise.md: the fit's, doubled for shared samples).
        assert abs(term["value"] - truth[key]) < 3.0 * term["std"], (key, term, truth[key])


def test_noise_refuses_a_mapping_without_a_channels_column(tmp_path):
    sc = gyrocal.Scenario.parse(STATIC_IMU)
    columns = write_static_imu(tmp_path / "s.csv", np.random.default_rng(1), 200, 20.0,
                               {"gx": 0.05, "gx_K": 1.0, "gz": 0.02, "ax": 20.0, "az": 50.0})
    del columns["az"]
    with pytest.raises(ValueError, match=r"^<arrays>: the record has no column az\.$"):
        gyrocal.noise(columns, sc)
