"""The Python module gives the command line's numbers bit for bit, and its errors are ValueErrors with the
command line's sentence (issue 10, item 3; docs/python.md).

ctest runs this file with Debian's /usr/bin/python3 -m pytest, PYTHONPATH=<build>/python and GYROCAL_CLI set to
the command line's executable (tests/CMakeLists.txt). Every expected value comes from the command line, through
its JSON or CSV text read back with Python's own parsers (json.loads, float(): both round-trip a double).
"""

import json
import math
import os
import subprocess

import numpy as np
import pytest

import gyrocal

CLI = os.environ.get("GYROCAL_CLI", "gyrocal")

# A short test so that each simulation and calibration takes a fraction of a second: 4 beta positions x 3
# revolutions at 9.9 rad/s, sampled at 100 Hz (about 1200 rows; at 50 Hz a sample step of 11 deg can miss the window
# means' 10 deg windows, and a revolution that misses one does not count), with the default scenario's machine errors.
SMALL_TEST = """
[test]
sample_rate_hz = 100.0
revolutions = 3
settle_s = 1.0
seed = 3
"""


def cli_result(text):
    """A result file of the command line as Python returns it: without gyrocal's marker and the command's own
    provenance (`gyrocal`, `config`, `plan`, and what the report states beyond the estimates: `unit_under_test`,
    `truth`, `test_sequence`, `position_inputs`), which only a file carries (docs/interface.md)."""
    result = json.loads(text)
    for key in ("gyrocal", "config", "plan", "unit_under_test", "truth", "test_sequence", "position_inputs"):
        result.pop(key, None)
    return result


def run_cli(*args, check=True):
    proc = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    if check:
        assert proc.returncode == 0, proc.stderr
    return proc


def cli_error(*args):
    """The command line's error sentence: its standard error without the 'gyrocal: ' prefix."""
    proc = run_cli(*args, check=False)
    assert proc.returncode == 1, (proc.returncode, proc.stdout, proc.stderr)
    prefix = "gyrocal: "
    assert proc.stderr.startswith(prefix)
    return proc.stderr[len(prefix):].rstrip("\n")


def read_record_csv(path):
    """The record's columns as written, each value through float() (exact for the writer's shortest form)."""
    header, rows = None, []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            if header is None:
                header = line.split(",")
            else:
                rows.append([float(v) for v in line.split(",")])
    return header, {name: [row[i] for row in rows] for i, name in enumerate(header)}


def write_record_csv(path, columns):
    """A record in gyrocal's format from Python (repr gives the shortest round-trip form)."""
    names = list(columns)
    with open(path, "w") as f:
        f.write("# gyrocal-record 1\n" + ",".join(names) + "\n")
        for row in zip(*(columns[n] for n in names)):
            f.write(",".join(repr(float(v)) for v in row) + "\n")


def same_bits(a, b):
    """Equal as doubles, bit for bit (so 0.0 differs from -0.0), for sequences of floats."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """The small configuration: its file, and the same as a Scenario."""
    path = tmp_path_factory.mktemp("config") / "small.toml"
    path.write_text(SMALL_TEST)
    return str(path), gyrocal.Scenario.load(str(path))


# --- Scenario ---------------------------------------------------------------------------------------------------

def test_scenario_to_toml_is_init_and_parses_back(small, tmp_path):
    out = tmp_path / "scenario.toml"
    run_cli("init", out)
    assert gyrocal.Scenario().to_toml() == out.read_text()
    config, sc = small
    again = gyrocal.Scenario.parse(sc.to_toml())
    assert (again.sample_rate_hz, again.seed, again.rate_rad_s) == (100.0, 3, 9.9)
    assert again.to_toml() == sc.to_toml()


# --- exact_inputs -----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("config", [None, "small"])
def test_exact_inputs_equal_cli_bit_for_bit(config, small):
    times = [0.0, 0.123456789, 1.0 / 3.0, 17.5, 1234.5678901]
    betas = [0.0, 90.0, 33.3, 270.0]
    scenario = gyrocal.Scenario() if config is None else small[1]
    config_args = [] if config is None else ["--config", small[0]]
    for beta in betas:
        omega, force = gyrocal.exact_inputs(scenario, time_s=np.array(times), beta_deg=beta)
        assert omega.shape == (len(times), 3) and force.shape == (len(times), 3)
        assert omega.dtype == np.float64 and force.dtype == np.float64
        for i, t in enumerate(times):
            out = run_cli("inputs", *config_args, "--time-s", repr(t), "--beta-deg", repr(beta), "--json", "-")
            expected = json.loads(out.stdout)
            assert same_bits(omega[i], expected["omega_rad_s"]), (t, beta, omega[i], expected["omega_rad_s"])
            assert same_bits(force[i], expected["specific_force_g"]), (t, beta)


def test_exact_inputs_take_a_number_or_a_one_dimensional_array():
    sc = gyrocal.Scenario()
    w1, f1 = gyrocal.exact_inputs(sc, time_s=2.5, beta_deg=90.0)
    w2, f2 = gyrocal.exact_inputs(sc, time_s=[0.0, 2.5], beta_deg=90)
    assert w1.shape == (1, 3) and w2.shape == (2, 3)
    assert same_bits(w1[0], w2[1]) and same_bits(f1[0], f2[1])
    # Physics, roughly (physics.md section 4): the counter-rotating platform cancels the main rate of 9.9 rad/s,
    # so the gyro sees about the Earth's rate; the specific force is gravity plus the centripetal omega^2 R (1 m).
    assert 5e-5 < np.linalg.norm(w1[0]) < 1e-3
    assert np.linalg.norm(f1[0]) == pytest.approx(math.hypot(1.0, 9.9**2 * 1.0 / 9.80665), rel=1e-2)


def test_exact_inputs_refuse_what_the_command_line_refuses():
    # issue 20, item 9: a beta or a time that is not finite, as `gyrocal inputs` refuses it, and a 2-D time array,
    # whose rows would otherwise be flattened silently into one list of instants.
    sc = gyrocal.Scenario()
    assert run_cli("inputs", "--beta-deg", "nan", "--time-s", "1", check=False).returncode != 0
    with pytest.raises(ValueError, match="beta_deg must be a finite number, not nan"):
        gyrocal.exact_inputs(sc, time_s=1.0, beta_deg=float("nan"))
    assert run_cli("inputs", "--beta-deg", "0", "--time-s", "inf", check=False).returncode != 0
    with pytest.raises(ValueError, match=r"time_s\[1\] must be a finite number, not inf"):
        gyrocal.exact_inputs(sc, time_s=[0.0, np.inf], beta_deg=0.0)
    with pytest.raises(ValueError, match="time_s has 2 dimensions"):
        gyrocal.exact_inputs(sc, time_s=[[0.0, 2.5]], beta_deg=0.0)


# --- simulate ---------------------------------------------------------------------------------------------------

def test_simulate_equals_cli_record_bit_for_bit(small, tmp_path):
    config, sc = small
    out = tmp_path / "rec.csv"
    run_cli("simulate", "--config", config, "--seed", 7, "--out", out)
    header, expected = read_record_csv(out)
    rec = gyrocal.simulate(sc, seed=7)
    assert list(rec) == header == list(gyrocal.RECORD_COLUMNS)
    assert len(expected["time_s"]) > 100
    for name in header:
        assert rec[name].dtype == np.float64
        assert same_bits(rec[name], expected[name]), name


def test_simulate_default_seed_is_the_scenarios(small, tmp_path):
    config, sc = small
    assert sc.seed == 3
    out = tmp_path / "rec.csv"
    run_cli("simulate", "--config", config, "--out", out)
    _, expected = read_record_csv(out)
    rec = gyrocal.simulate(sc)
    assert same_bits(rec["gyro_deg_h"], expected["gyro_deg_h"])
    # Another seed gives another noise (so the test above does compare the seed).
    assert not same_bits(gyrocal.simulate(sc, seed=4)["gyro_deg_h"], expected["gyro_deg_h"])


def test_simulate_refuses_a_seed_that_is_not_a_non_negative_integer(small):
    # issue 20, item 9: a ValueError as for every other bad argument (pybind11 raised TypeError for -1).
    _, sc = small
    for seed in (-1, 2**64, 1.5, "3"):
        with pytest.raises(ValueError, match="seed must be an integer from 0 to 18446744073709551615"):
            gyrocal.simulate(sc, seed=seed)
    # The largest seed and a NumPy integer are seeds.
    assert len(gyrocal.simulate(sc, seed=2**64 - 1)["time_s"]) == len(gyrocal.simulate(sc, seed=np.uint64(5))["time_s"])


# --- calibrate --------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("method,compensation,reduction", [
    ("least-squares", "full", "harmonic"),
    ("closed-form", "seed", "window"),
])
def test_calibrate_from_arrays_and_path_equal_cli(small, tmp_path, method, compensation, reduction):
    config, sc = small
    record = tmp_path / "rec.csv"
    run_cli("simulate", "--config", config, "--seed", 11, "--out", record)
    result = tmp_path / "result.json"
    run_cli("calibrate", record, "--config", config, "--method", method, "--compensation", compensation,
            "--reduction", reduction, "--json", result)
    expected = cli_result(result.read_text())

    from_path = gyrocal.calibrate(str(record), sc, method=method, compensation=compensation, reduction=reduction)
    assert from_path == expected

    rec = gyrocal.simulate(sc, seed=11)
    from_arrays = gyrocal.calibrate(rec, sc, method=method, compensation=compensation, estimate=[],
                                    reduction=reduction)
    # The same result but for the record's name, which messages carry too.
    name = expected.pop("record")
    assert name == str(record)
    assert from_arrays.pop("record") == "<arrays>"
    expected["warnings"] = [w.replace(name, "<arrays>") for w in expected["warnings"]]
    assert from_arrays == expected
    # Not vacuous: the result holds the estimated coefficients.
    values = [c["value"] for c in from_arrays["coefficients"].values() if c["identifiable"]]
    assert len(from_arrays["coefficients"]) == 10 and len(values) >= 5 and all(map(math.isfinite, values))


def test_calibrate_takes_the_scenarios_reduction_and_reduce_options(tmp_path):
    # [calibration] reduction and [reduce] as `gyrocal calibrate --config` takes them: reduction=None keeps the
    # scenario's method, a named one overrides it, and the [reduce] options apply either way.
    config = tmp_path / "window.toml"
    config.write_text(SMALL_TEST + '[calibration]\nreduction = "window"\n[reduce]\nwindow_deg = 20.0\n')
    sc = gyrocal.Scenario.load(str(config))
    record = tmp_path / "rec.csv"
    run_cli("simulate", "--config", config, "--out", record)
    for flag, reduction in [([], None), (["--reduction", "harmonic"], "harmonic")]:
        result = tmp_path / "result.json"
        run_cli("calibrate", record, "--config", config, *flag, "--json", result)
        expected = cli_result(result.read_text())
        assert gyrocal.calibrate(str(record), sc, reduction=reduction) == expected
    # Not vacuous: the scenario's window of 20 deg changes the result from the default window's.
    plain = tmp_path / "plain.toml"
    plain.write_text(SMALL_TEST)
    with_default_window = gyrocal.calibrate(str(record), gyrocal.Scenario.load(str(plain)), reduction="window")
    assert gyrocal.calibrate(str(record), sc)["coefficients"] != with_default_window["coefficients"]


def test_calibrate_takes_the_scenarios_gyro_model_and_estimate(tmp_path):
    # issue 20, item 9: [calibration] gyro_model and estimate apply in Python as on the command line (the options
    # are built by one library function): drift+rate gives the 13 coefficients, the estimate its machine error.
    config = tmp_path / "rate.toml"
    config.write_text(SMALL_TEST + '[calibration]\ngyro_model = "drift+rate"\nestimate = ["counter_perpendicularity_x"]\n')
    sc = gyrocal.Scenario.load(str(config))
    record = tmp_path / "rec.csv"
    run_cli("simulate", "--config", config, "--out", record)
    result = tmp_path / "result.json"
    run_cli("calibrate", record, "--config", config, "--json", result)
    expected = cli_result(result.read_text())
    assert len(expected["coefficients"]) == 13 and len(expected["machine_errors"]) == 1
    got = gyrocal.calibrate(str(record), sc)
    assert got == expected
    assert len(got["coefficients"]) == 13
    assert [e["error"] for e in got["machine_errors"]] == ["counter_perpendicularity_x"]
    # The call's own choices override the scenario's, as --gyro-model and --estimate do.
    run_cli("calibrate", record, "--config", config, "--gyro-model", "drift", "--estimate", "counter_rate_mismatch",
            "--json", result)
    overridden = gyrocal.calibrate(str(record), sc, gyro_model="drift", estimate=["counter_rate_mismatch"])
    assert overridden == cli_result(result.read_text())
    assert len(overridden["coefficients"]) == 10
    # An empty list estimates nothing (the command line has no way to say so but leaving out [calibration]).
    assert "machine_errors" not in gyrocal.calibrate(str(record), sc, estimate=[])
    with pytest.raises(ValueError, match="unknown gyro model 'rate'"):
        gyrocal.calibrate(str(record), sc, gyro_model="rate")


def test_coefficients_come_in_the_contract_order(small, tmp_path):
    # docs/contract.md orders the coefficients dF dI dO dS dII dOO dSS dIO dIS dOS; the command line's JSON and the
    # module's dict keep that order (json.loads keeps the text's order), not the alphabet's.
    config, sc = small
    contract = ["dF", "dI", "dO", "dS", "dII", "dOO", "dSS", "dIO", "dIS", "dOS"]
    record = tmp_path / "rec.csv"
    run_cli("simulate", "--config", config, "--out", record)
    cli = run_cli("calibrate", record, "--config", config, "--json", "-")
    assert list(json.loads(cli.stdout)["coefficients"]) == contract
    assert list(gyrocal.calibrate(str(record), sc)["coefficients"]) == contract
    rate = gyrocal.calibrate(str(record), sc, gyro_model="drift+rate")
    assert list(rate["coefficients"]) == contract + [
        "scale_factor_error_ppm", "input_axis_misalignment_O_arcsec", "input_axis_misalignment_S_arcsec"]


def test_calibrate_takes_a_mapping_with_more_columns(small):
    _, sc = small
    rec = gyrocal.simulate(sc, seed=2)
    plain = gyrocal.calibrate(rec, sc)
    rec["temperature_c"] = np.full_like(rec["time_s"], 20.0)
    rec = {k: list(v) for k, v in reversed(rec.items())}  # lists, other order: columns are taken by name
    assert gyrocal.calibrate(rec, sc) == plain


# --- noise ------------------------------------------------------------------------------------------------------

def test_noise_from_path_and_arrays_equal_cli(tmp_path):
    rng = np.random.default_rng(5)
    n = 4000
    columns = {
        "time_s": np.arange(n) / 100.0,
        "main_angle_deg": np.zeros(n),
        "counter_angle_deg": np.zeros(n),
        "position_angle_deg": np.zeros(n),
        # white noise plus a random walk on a large offset (a sensor's raw zero)
        "gyro_deg_h": 1e4 + rng.normal(0.0, 3.0, n) + np.cumsum(rng.normal(0.0, 0.05, n)),
    }
    record = tmp_path / "static.csv"
    write_record_csv(record, columns)
    result = tmp_path / "noise.json"
    run_cli("noise", record, "--json", result)
    expected = cli_result(result.read_text())
    assert len(expected["allan"]) > 5

    assert gyrocal.noise(str(record), gyrocal.Scenario()) == expected
    from_arrays = gyrocal.noise({"time_s": columns["time_s"], "gyro_deg_h": columns["gyro_deg_h"]})
    assert from_arrays.pop("record") == "<arrays>"
    expected.pop("record")
    assert from_arrays == expected


def test_a_mapped_record_reads_through_the_scenarios_record_section(small, tmp_path):
    """A rig's own layout (docs/records.md): ';', ms stamps, angles in radians, the output in mV, no magic line and
    no angle columns for noise. The module reads a path through the scenario's [record], as --config does."""
    config, _ = small
    rec = gyrocal.simulate(gyrocal.Scenario.load(config), seed=4)
    mapped_config = tmp_path / "rig.toml"
    mapped_config.write_text(open(config).read() + """
[record]
delimiter = ";"
time_column = "t_ms"
time_unit = "ms"
main_angle_column = "theta"
counter_angle_column = "psi"
position_angle_column = "beta"
angle_unit = "rad"
output_column = "U_mV"
output_scale_per_deg_h = 4.0
""")
    sc = gyrocal.Scenario.load(str(mapped_config))
    record = tmp_path / "rig.csv"
    with open(record, "w") as f:
        f.write("U_mV;t_ms;beta;theta;psi\n")
        for w, t, b, m, c in zip(rec["gyro_deg_h"], rec["time_s"], rec["position_angle_deg"], rec["main_angle_deg"],
                                 rec["counter_angle_deg"]):
            f.write(f"{w * 4.0!r};{round(t * 1000)};{math.radians(b)!r};{math.radians(m)!r};{math.radians(c)!r}\n")
    expected = cli_result(run_cli("calibrate", record, "--config", mapped_config, "--json", "-").stdout)
    assert gyrocal.calibrate(str(record), sc) == expected
    native = gyrocal.calibrate(rec, sc)
    for name, c in native["coefficients"].items():
        if c["identifiable"]:
            assert abs(expected["coefficients"][name]["value"] - c["value"]) <= 1e-6 * c["std"], name
    # noise refuses a record whose angles turn, naming the motion (docs/interface.md), in Python as on the command
    # line; a [record] naming only the time and the output (the angle columns absent) reads its output as it is.
    with pytest.raises(ValueError, match="the record is not static: the main axis turns at "):
        gyrocal.noise(str(record), sc)
    output_only = tmp_path / "output_only.toml"
    output_only.write_text('[record]\ndelimiter = ";"\ntime_column = "t_ms"\ntime_unit = "ms"\n'
                           'output_column = "U_mV"\noutput_scale_per_deg_h = 4.0\n')
    expected_noise = cli_result(run_cli("noise", record, "--config", output_only, "--json", "-").stdout)
    assert gyrocal.noise(str(record), gyrocal.Scenario.load(str(output_only))) == expected_noise
    with pytest.raises(ValueError, match="this is not a gyrocal record"):
        gyrocal.noise(str(record))


def test_noise_of_a_record_of_the_output_alone_equals_the_full_records(tmp_path):
    """gyrocal's own header time_s,gyro_deg_h (a noise logger's record) gives the full record's Allan deviation."""
    rng = np.random.default_rng(6)
    n = 2000
    time_s = np.arange(n) / 50.0
    rate = 9.5 + rng.normal(0.0, 2.0, n)
    full = tmp_path / "full.csv"
    write_record_csv(full, {"time_s": time_s, "main_angle_deg": np.zeros(n), "counter_angle_deg": np.zeros(n),
                            "position_angle_deg": np.full(n, 90.0), "gyro_deg_h": rate})
    alone = tmp_path / "alone.csv"
    write_record_csv(alone, {"time_s": time_s, "gyro_deg_h": rate})
    from_full, from_alone = gyrocal.noise(str(full)), gyrocal.noise(str(alone))
    assert from_alone["allan"] == from_full["allan"]
    assert from_alone == cli_result(run_cli("noise", alone, "--json", "-").stdout)


# --- errors -----------------------------------------------------------------------------------------------------

def test_bad_configuration_raises_value_error_with_cli_sentence(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[test]\nrevolutions = 3\nsample_rate_hz = -5.0\n")
    message = cli_error("inputs", "--config", bad, "--beta-deg", 0, "--time-s", 0)
    assert "sample_rate_hz" in message
    with pytest.raises(ValueError) as e:
        gyrocal.Scenario.load(str(bad))
    assert str(e.value) == message


def test_bad_record_raises_value_error_with_cli_sentence(small, tmp_path):
    config, sc = small
    record = tmp_path / "broken.csv"
    record.write_text("# gyrocal-record 1\ntime_s,main_angle_deg,counter_angle_deg,position_angle_deg,gyro_deg_h\n"
                      "0,0,0,0,1\n0.02,1,0,0,x\n")
    for args, call in [
        (("calibrate", record, "--config", config), lambda: gyrocal.calibrate(str(record), sc)),
        (("noise", record), lambda: gyrocal.noise(str(record), sc)),
    ]:
        message = cli_error(*args)
        assert "line 4" in message
        with pytest.raises(ValueError) as e:
            call()
        assert str(e.value) == message
    missing = str(tmp_path / "missing.csv")
    message = cli_error("calibrate", missing)
    with pytest.raises(ValueError) as e:
        gyrocal.calibrate(missing, gyrocal.Scenario())
    assert str(e.value) == message


def test_bad_arrays_and_options_raise_value_error(small):
    _, sc = small
    rec = gyrocal.simulate(sc, seed=1)
    with pytest.raises(ValueError, match="estimate: unknown machine error 'counter_rate_offset'"):
        gyrocal.calibrate(rec, sc, estimate=["counter_rate_offset"])
    with pytest.raises(ValueError, match="unknown method 'fast'"):
        gyrocal.calibrate(rec, sc, method="fast")
    with pytest.raises(ValueError, match="no column gyro_deg_h"):
        gyrocal.calibrate({k: v for k, v in rec.items() if k != "gyro_deg_h"}, sc)
    backwards = dict(rec)
    backwards["time_s"] = rec["time_s"].copy()
    backwards["time_s"][10] = backwards["time_s"][9]
    with pytest.raises(ValueError, match="row 10: time_s .* does not increase"):
        gyrocal.calibrate(backwards, sc)
    nan = dict(rec)
    nan["gyro_deg_h"] = rec["gyro_deg_h"].copy()
    nan["gyro_deg_h"][5] = np.nan
    with pytest.raises(ValueError, match="row 5: gyro_deg_h is nan"):
        gyrocal.calibrate(nan, sc)
    short = dict(rec)
    short["main_angle_deg"] = rec["main_angle_deg"][:-1]
    with pytest.raises(ValueError, match="column main_angle_deg has"):
        gyrocal.calibrate(short, sc)


def test_estimate_gives_machine_errors(small):
    # Self-calibration through the module (docs/self_calibration.md): the small test has one speed, so the
    # counter platform's perpendicularity is reported, not identifiable, with the reason.
    _, sc = small
    rec = gyrocal.simulate(sc, seed=1)
    res = gyrocal.calibrate(rec, sc, estimate="counter_perpendicularity_x")
    (entry,) = res["machine_errors"]
    assert entry["error"] == "counter_perpendicularity_x"
    assert entry["unit"] == "arcsec"
    assert entry["identifiable"] is False
    assert "second non-zero speed" in entry["reason"]


# --- an accelerometer (issue 19; docs/accelerometer.md) ---------------------------------------------------------

ACCELEROMETER = """
[sensor]
kind = "accelerometer"

[test]
rates_rad_s = [0.0, 6.0, 12.0]
revolutions = 4
sample_rate_hz = 50.0
static_hold_s = 2.0
seed = 5

[uncertainty]
radius_error_m = 5e-6
"""

ACCELEROMETER_ORDER = ["K0", "K1", "K2", "K3", "Kip", "Kio", "Kpo", "Kpp", "Koo", "delta_p", "delta_o"]


def test_an_accelerometer_simulates_and_calibrates_as_the_command_line(tmp_path):
    # Two speeds and a static set: all eleven identifiable. The record's output column is accel_g, the
    # coefficients come in the accelerometer's table order and units, from a path and from arrays alike.
    config = tmp_path / "accel.toml"
    config.write_text(ACCELEROMETER)
    sc = gyrocal.Scenario.load(str(config))
    record = tmp_path / "rec.csv"
    run_cli("simulate", "--config", config, "--out", record)
    header, expected_rows = read_record_csv(record)
    rec = gyrocal.simulate(sc)
    assert list(rec) == header == list(gyrocal.RECORD_COLUMNS[:4]) + ["accel_g"]
    for name in header:
        assert same_bits(rec[name], expected_rows[name]), name

    expected = cli_result(run_cli("calibrate", record, "--config", config, "--estimate", "radius_error",
                                  "--json", "-").stdout)
    assert list(expected["coefficients"]) == ACCELEROMETER_ORDER
    assert expected["sensor"] == "accelerometer"
    from_path = gyrocal.calibrate(str(record), sc, estimate="radius_error")
    assert from_path == expected
    from_arrays = gyrocal.calibrate(rec, sc, estimate="radius_error")
    name = expected.pop("record")
    assert from_arrays.pop("record") == "<arrays>"
    expected["warnings"] = [w.replace(name, "<arrays>") for w in expected["warnings"]]
    assert from_arrays == expected
    # Not vacuous: every coefficient identified, K1 near its truth of 1, the radius error estimated.
    assert all(c["identifiable"] for c in from_arrays["coefficients"].values())
    assert abs(from_arrays["coefficients"]["K1"]["value"] - 1.0) < 1e-4
    assert [e["error"] for e in from_arrays["machine_errors"]] == ["radius_error"]
    assert from_arrays["coefficients"]["delta_p"]["unit"] == "urad"


def test_an_output_beyond_the_bound_is_refused_naming_the_row():
    # issue 29, D13: the arrays' output is held to limits::kOutputMagnitude (1e50) as the record reader holds it;
    # a 1e308 sample made noise ask "is the output constant?", a dwell of them calibrate say "too few revolutions".
    rng = np.random.default_rng(1)
    t = np.arange(1000) * 0.01
    w = rng.standard_normal(1000)
    w[417] = 1e308
    with pytest.raises(ValueError, match=r"<arrays>, row 417: gyro_deg_h is 1e\+308; an output is at most 1e\+50"):
        gyrocal.noise({"time_s": t, "gyro_deg_h": w})
    zeros = np.zeros(1000)
    with pytest.raises(ValueError, match=r"row 417: gyro_deg_h is 1e\+308"):
        gyrocal.calibrate({"time_s": t, "main_angle_deg": zeros, "counter_angle_deg": zeros,
                           "position_angle_deg": zeros, "gyro_deg_h": w}, gyrocal.Scenario())
