"""gyrocal from Python: the same library as the command line, so the same numbers (docs/python.md).

    import numpy as np, gyrocal
    sc = gyrocal.Scenario.load("scenario.toml")        # gyrocal.Scenario() is the default scenario
    w, f = gyrocal.exact_inputs(sc, time_s=np.linspace(0, 10, 1000), beta_deg=90.0)  # (n, 3): rad/s, g
    rec = gyrocal.simulate(sc, seed=1)                 # dict of numpy arrays named as the record's columns
    res = gyrocal.calibrate(rec, sc, method="least-squares", compensation="full")
    nz = gyrocal.noise("static.csv", sc)               # noise's JSON as a dict

Every error of gyrocal raises ValueError with the command line's sentence.
"""

import operator
import os

import numpy as np

from ._gyrocal import Scenario
from . import _gyrocal

__all__ = ["Scenario", "exact_inputs", "simulate", "calibrate", "noise", "RECORD_COLUMNS"]

#: The record's required columns, in order (docs/contract.md, "Record (CSV)").
RECORD_COLUMNS = ("time_s", "main_angle_deg", "counter_angle_deg", "position_angle_deg", "gyro_deg_h")

#: What a record given as arrays is called in messages and in the result's "record".
_ARRAYS_NAME = "<arrays>"


def _is_path(rec):
    return isinstance(rec, (str, os.PathLike))


def _column(rec, name):
    try:
        values = rec[name]
    except (KeyError, IndexError, TypeError):
        raise ValueError(f"{_ARRAYS_NAME}: the record has no column {name}.") from None
    return np.ascontiguousarray(values, dtype=np.float64)


#: gyrocal's own output columns: a gyro's (deg/h) and an accelerometer's (g).
_GYRO_COLUMN = "gyro_deg_h"
_ACCEL_COLUMN = "accel_g"


def _has_column(rec, name):
    try:
        rec[name]
    except (KeyError, IndexError, TypeError):
        return False
    return True


def _output_column(rec, scenario):
    """The output column of the scenario's sensor (gyro_deg_h or accel_g); a mapping that holds the other
    sensor's column instead raises ValueError naming it and the scenario's [sensor] kind."""
    column = scenario.output_column
    other = _ACCEL_COLUMN if column == _GYRO_COLUMN else _GYRO_COLUMN
    if not _has_column(rec, column) and _has_column(rec, other):
        _gyrocal._check_output_column(other, scenario, _ARRAYS_NAME)
    return column


def exact_inputs(scenario, time_s, beta_deg):
    """Exact inputs to the gyro at the instants time_s (s) of a dwell at the scenario's rate and beta_deg,
    as `gyrocal inputs --time-s T --beta-deg B`: (omega, specific_force), each an (n, 3) float64 array of
    the I, O, S components, rad/s and g. time_s is a number or a one-dimensional array; an array of more
    dimensions, or a value that is not finite (as beta_deg), raises ValueError as the command line refuses
    it."""
    t = np.ascontiguousarray(time_s, dtype=np.float64)
    if t.ndim == 0:
        t = t.reshape(1)
    return _gyrocal._exact_inputs(scenario, t, float(beta_deg))


#: The largest seed: the simulation's seed is an unsigned 64-bit integer, as --seed.
_MAX_SEED = 2**64 - 1


def simulate(scenario, seed=None):
    """The record `gyrocal simulate --seed SEED` writes, held in memory: a dict of float64 arrays named as the
    record's columns (RECORD_COLUMNS; an accelerometer's output is keyed accel_g, in g, as its record's header). seed=None takes the scenario's [test] seed, as without --seed; any other
    seed is an integer from 0 to 2**64 - 1 (ValueError otherwise)."""
    if seed is not None:
        try:
            value = operator.index(seed)
        except TypeError:
            raise ValueError(f"seed must be an integer from 0 to {_MAX_SEED}, not {seed!r}.") from None
        if not 0 <= value <= _MAX_SEED:
            raise ValueError(f"seed must be an integer from 0 to {_MAX_SEED}, not {value}.")
        seed = value
    return _gyrocal._simulate(scenario, seed)


def calibrate(rec, scenario, method="least-squares", compensation="full", estimate=None, reduction=None,
              gyro_model=None):
    """`gyrocal calibrate --json` as a dict. rec is a record's path (read through the scenario's [record]
    layout when its configuration has one, as `gyrocal calibrate --config`) or a mapping of arrays (a dict such
    as simulate() returns, a pandas DataFrame, ...) holding RECORD_COLUMNS (with accel_g for the output of an
    accelerometer's scenario; the other sensor's column is refused by name); other columns are ignored.
    method: "least-squares" or "closed-form"; compensation: "none", "seed" or "full"; reduction: "harmonic" or
    "window"; gyro_model: "drift" or "drift+rate"; estimate: machine errors estimated with the coefficients
    (self-calibration, as --estimate: NAME, NAME_I/_O/_S, NAME:N; docs/self_calibration.md), a list of names or
    one name ([] estimates none). Each of reduction, gyro_model and estimate left None takes the scenario's
    [calibration] value, as the command line does without the option; the scenario's [reduce] options apply
    always. The options are built by the command line's own function, so the result is its result. The
    coefficients come in the contract's order (dF dI dO dS dII dOO dSS dIO dIS dOS, then the rate errors); an
    accelerometer's scenario ([sensor] kind) gives its eleven in its table's order (K0 K1 K2 K3 Kip Kio Kpo
    Kpp Koo delta_p delta_o), from a record whose output column is accel_g."""
    if isinstance(estimate, str):
        estimate = [estimate]
    if estimate is not None:
        estimate = [str(name) for name in estimate]
    reduction = "" if reduction is None else str(reduction)
    gyro_model = "" if gyro_model is None else str(gyro_model)
    options = (method, compensation, reduction, estimate, gyro_model)
    if _is_path(rec):
        return _gyrocal._calibrate_path(os.fspath(rec), scenario, *options)
    names = RECORD_COLUMNS[:4] + (_output_column(rec, scenario),)
    columns = [_column(rec, name) for name in names]
    return _gyrocal._calibrate_arrays(*columns, scenario, *options, _ARRAYS_NAME)


def noise(rec, scenario=None):
    """`gyrocal noise --json` as a dict: the overlapping Allan deviation of the record's output and the fitted
    IEEE 952 terms. rec is a record's path or a mapping of arrays holding time_s and the output: gyro_deg_h
    (a gyro's, deg/h) or accel_g (an accelerometer's, g; its terms keyed as [accelerometer.noise], in ug).
    A record's path is read through the scenario's [record] layout when it has one (as `gyrocal noise
    --config`), and the scenario's [sensor] kind says whose output it must hold; without a scenario the
    record's output column says. The noise itself does not depend on the scenario."""
    if _is_path(rec):
        return _gyrocal._noise_path(os.fspath(rec), scenario)
    if scenario is not None:
        column = _output_column(rec, scenario)
    else:
        column = _ACCEL_COLUMN if _has_column(rec, _ACCEL_COLUMN) and not _has_column(rec, _GYRO_COLUMN) \
            else _GYRO_COLUMN
    return _gyrocal._noise_arrays(_column(rec, "time_s"), _column(rec, column), column, _ARRAYS_NAME)
