"""Every bad argument of the Python module raises ValueError carrying one sentence that names the argument (issue 29,
D16; docs/python.md, "Arguments"). An argument of a plainly wrong Python type (None for a scenario, a number for a
method) raises gyrocal.ArgumentTypeError, which is both a TypeError and a ValueError, with one sentence, never
pybind11's listing of signatures. A path may be str, bytes or os.PathLike, as for Python's open().
"""

import os
import subprocess

import numpy as np
import pytest

import gyrocal

CLI = os.environ.get("GYROCAL_CLI", "gyrocal")

SMALL_TEST = """
[test]
sample_rate_hz = 100.0
revolutions = 3
settle_s = 1.0
seed = 3
"""


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """The small configuration as a Scenario, and a record of it written by the command line."""
    folder = tmp_path_factory.mktemp("bad-arguments")
    config = folder / "small.toml"
    config.write_text(SMALL_TEST)
    record = folder / "rec.csv"
    subprocess.run([CLI, "simulate", "--config", str(config), "--out", str(record)], check=True,
                   capture_output=True)
    return gyrocal.Scenario.load(str(config)), str(record)


def refused(call, *words, kind=ValueError):
    """The sentence `call` is refused with: a `kind` (ValueError by default), on one line, without pybind11's
    listing, holding each of `words`."""
    with pytest.raises(kind) as e:
        call()
    message = str(e.value)
    assert isinstance(e.value, ValueError), (type(e.value), message)
    assert "\n" not in message, message
    for noise in ("incompatible function arguments", "Invoked with", "AttributeError", "NoneType' object"):
        assert noise not in message, message
    for word in words:
        assert word in message, (word, message)
    return message


def wrong_type(call, *words):
    """Refused as a plainly wrong Python type: a TypeError that is also a ValueError."""
    return refused(call, *words, kind=TypeError)


# --- the scenario -----------------------------------------------------------------------------------------------

def test_a_scenario_that_is_not_one_is_refused_by_name(small):
    sc, record = small
    rec = gyrocal.simulate(sc, seed=1)
    wrong_type(lambda: gyrocal.calibrate(rec, None), "scenario", "gyrocal.Scenario", "None")
    wrong_type(lambda: gyrocal.calibrate(record, None), "scenario", "None")
    wrong_type(lambda: gyrocal.noise(rec, "s.toml"), "scenario", "gyrocal.Scenario", "str")
    wrong_type(lambda: gyrocal.noise(record, 5), "scenario", "int")
    wrong_type(lambda: gyrocal.simulate("s.toml"), "scenario", "str")
    wrong_type(lambda: gyrocal.exact_inputs(None, 0.0, 0.0), "scenario", "None")
    # noise's scenario is optional: None is no scenario.
    assert gyrocal.noise(rec, None) == gyrocal.noise(rec)


# --- text options -----------------------------------------------------------------------------------------------

def test_method_and_compensation_none_are_their_defaults(small):
    sc, _ = small
    rec = gyrocal.simulate(sc, seed=1)
    default = gyrocal.calibrate(rec, sc)
    assert gyrocal.calibrate(rec, sc, method=None, compensation=None) == default


def test_options_of_the_wrong_type_are_refused_by_name(small):
    sc, _ = small
    rec = gyrocal.simulate(sc, seed=1)
    wrong_type(lambda: gyrocal.calibrate(rec, sc, compensation=5), "compensation", "int")
    wrong_type(lambda: gyrocal.calibrate(rec, sc, method=["closed-form"]), "method", "list")
    wrong_type(lambda: gyrocal.calibrate(rec, sc, reduction=1.0), "reduction", "float")
    wrong_type(lambda: gyrocal.calibrate(rec, sc, gyro_model=b"drift"), "gyro_model", "bytes")
    wrong_type(lambda: gyrocal.calibrate(rec, sc, estimate=5), "estimate", "int")
    wrong_type(lambda: gyrocal.calibrate(rec, sc, estimate=["counter_wobble_x", 3]), "estimate", "int")
    # A value of the right type that is no choice keeps the command line's sentence.
    refused(lambda: gyrocal.calibrate(rec, sc, compensation="most"), "compensation", "most")


def test_a_nul_character_in_a_text_is_refused_before_it_cuts_the_sentence(small):
    sc, record = small
    message = refused(lambda: gyrocal.Scenario.parse("[test]\nfoo = 1\n", name="a\x00b"), "name", "NUL")
    assert "'a\\x00b'" in message, message
    refused(lambda: gyrocal.calibrate(gyrocal.simulate(sc, seed=1), sc, method="closed\x00form"), "method", "NUL")
    # A path with a NUL would be opened up to the NUL (the record itself): refused instead, as open() does.
    refused(lambda: gyrocal.calibrate(record + "\x00.bak", sc), "rec", "NUL")
    refused(lambda: gyrocal.noise(record + "\x00"), "rec", "NUL")
    refused(lambda: gyrocal.Scenario.load("s.toml\x00"), "path", "NUL")


# --- records and paths ------------------------------------------------------------------------------------------

def test_a_bytes_or_path_like_path_is_a_path(small):
    sc, record = small
    import pathlib
    expected = gyrocal.calibrate(record, sc)
    assert gyrocal.calibrate(os.fsencode(record), sc) == expected
    assert gyrocal.calibrate(pathlib.Path(record), sc) == expected
    # The record turns, so noise refuses it: by its path, read as a path (before, bytes were taken for a mapping
    # and the sentence was "the record has no column time_s").
    with pytest.raises(ValueError) as from_str:
        gyrocal.noise(record)
    message = refused(lambda: gyrocal.noise(os.fsencode(record)), record, "is not static")
    assert message == str(from_str.value)


def test_a_record_that_is_neither_a_path_nor_a_mapping_is_refused(small):
    sc, _ = small
    wrong_type(lambda: gyrocal.calibrate(None, sc), "rec", "None")
    wrong_type(lambda: gyrocal.noise(3.5), "rec", "float")


def test_a_column_that_does_not_hold_numbers_is_refused_by_name(small):
    sc, _ = small
    rec = dict(gyrocal.simulate(sc, seed=1))
    rec["gyro_deg_h"] = None
    wrong_type(lambda: gyrocal.calibrate(rec, sc), "column gyro_deg_h", "None")
    rec = dict(gyrocal.simulate(sc, seed=1))
    rec["time_s"] = [str(t) for t in rec["time_s"]]
    wrong_type(lambda: gyrocal.noise(rec), "column time_s", "str")


# --- exact_inputs -----------------------------------------------------------------------------------------------

def test_exact_inputs_refuse_what_is_not_a_number(small):
    sc, _ = small
    wrong_type(lambda: gyrocal.exact_inputs(sc, None, 0), "time_s", "None")
    wrong_type(lambda: gyrocal.exact_inputs(sc, ["1.0"], 0), "time_s", "str")
    wrong_type(lambda: gyrocal.exact_inputs(sc, [1.0, None], 0), "time_s", "None")
    wrong_type(lambda: gyrocal.exact_inputs(sc, 1.0, None), "beta_deg", "None")
    wrong_type(lambda: gyrocal.exact_inputs(sc, 1.0, "90"), "beta_deg", "str")
    # Numbers of any NumPy or Python kind are numbers.
    w, _ = gyrocal.exact_inputs(sc, np.float32(1.0), np.int64(90))
    assert w.shape == (1, 3)
    w, _ = gyrocal.exact_inputs(sc, [0, 1, 2], 90)
    assert w.shape == (3, 3)


# --- Scenario.parse and Scenario.load ---------------------------------------------------------------------------

def test_parse_refuses_an_empty_configuration_as_load_does(tmp_path):
    empty = tmp_path / "empty.toml"
    empty.write_text("")
    refused(lambda: gyrocal.Scenario.load(str(empty)), "empty.toml is empty")
    refused(lambda: gyrocal.Scenario.parse(""), "<string> is empty", "gyrocal.Scenario()")
    refused(lambda: gyrocal.Scenario.parse(" \n\t\r\n", name="blank"), "blank is empty (white space only)")
    # Comments alone are a choice of every default, in a file as in a text.
    assert gyrocal.Scenario.parse("# every default\n").to_toml() == gyrocal.Scenario().to_toml()


def test_parse_refuses_text_beyond_the_configurations_limit():
    limit = 1 << 20
    refused(lambda: gyrocal.Scenario.parse("#" * limit + "\n"), "<string>", "larger than 1 MiB")


def test_parse_and_load_refuse_arguments_of_the_wrong_type(tmp_path):
    wrong_type(lambda: gyrocal.Scenario.parse(None), "text", "None")
    wrong_type(lambda: gyrocal.Scenario.parse(b"[test]\n"), "text", "bytes")
    wrong_type(lambda: gyrocal.Scenario.parse("[test]\n", name=3), "name", "int")
    wrong_type(lambda: gyrocal.Scenario.load(None), "path", "None")
    config = tmp_path / "c.toml"
    config.write_text(SMALL_TEST)
    assert gyrocal.Scenario.load(os.fsencode(config)).to_toml() == gyrocal.Scenario.load(config).to_toml()


def test_exact_inputs_refuses_an_instant_beyond_the_longest_test():
    # As `gyrocal inputs --time-s`: 1e10 samples at the scenario's 200 Hz are 5e7 s; beyond it theta = Omega t
    # loses every digit and then overflows (1e308 gave NaN arrays).
    sc = gyrocal.Scenario()
    for t in (1e308, -1e308, 1e9):
        refused(lambda: gyrocal.exact_inputs(sc, t, 0.0), "time_s[0] must be between", "5e+07 s")
    refused(lambda: gyrocal.exact_inputs(sc, [0.0, 6e7], 0.0), "time_s[1]")
    omega, force = gyrocal.exact_inputs(sc, 4e7, 0.0)
    assert np.isfinite(omega).all() and np.isfinite(force).all()
