"""gyrocal from Python: the same library as the command line, so the same numbers (docs/python.md).

    import numpy as np, gyrocal
    sc = gyrocal.Scenario.load("scenario.toml")        # gyrocal.Scenario() is the default scenario
    w, f = gyrocal.exact_inputs(sc, time_s=np.linspace(0, 10, 1000), beta_deg=90.0)  # (n, 3): rad/s, g
    rec = gyrocal.simulate(sc, seed=1)                 # dict of numpy arrays named as the record's columns
    res = gyrocal.calibrate(rec, sc, method="least-squares", compensation="full")
    nz = gyrocal.noise("static.csv", sc)               # noise's JSON as a dict
    h = gyrocal.history("gyrocal-history.sqlite", "SN123")  # `history show --json` as a dict, with arrays

Every error of gyrocal raises ValueError with the command line's sentence; an argument of a plainly wrong Python
type raises ArgumentTypeError, a TypeError that is also a ValueError, naming the argument in one sentence.
"""

import functools
import inspect
import numbers
import operator
import os

import numpy as np

from ._gyrocal import Scenario
from . import _gyrocal

__all__ = ["Scenario", "exact_inputs", "simulate", "calibrate", "noise", "imu_columns", "history",
           "RECORD_COLUMNS", "ArgumentTypeError"]

#: The record's required columns, in order (docs/contract.md, "Record (CSV)").
RECORD_COLUMNS = ("time_s", "main_angle_deg", "counter_angle_deg", "position_angle_deg", "gyro_deg_h")

#: What a record given as arrays is called in messages and in the result's "record".
_ARRAYS_NAME = "<arrays>"


# --- arguments ---------------------------------------------------------------------------------------------------
# Every public function's arguments are checked here, by the decorator _arguments and one check per kind of
# argument, before anything reaches the compiled part (docs/python.md, "Arguments"): a bad argument raises a
# ValueError with one sentence naming it; a plainly wrong Python type raises ArgumentTypeError, which is both a
# TypeError and a ValueError. pybind11 never sees a wrong type, so its listing of signatures never shows.


class ArgumentTypeError(TypeError, ValueError):
    """An argument of a plainly wrong Python type (None for a scenario, a number for a method), named in one
    sentence. A TypeError, as Python raises for a wrong type, and a ValueError, as every refusal of gyrocal is."""


def _type_name(value):
    return "None" if value is None else type(value).__name__


def _no_nul(text, argument):
    """`text`, refused if it holds a NUL character: no file name or option holds one, and a sentence holding it
    would be cut short at it."""
    if "\x00" in text:
        shown = text if len(text) <= 80 else text[:77] + "..."
        raise ValueError(f"{argument} {shown!r} holds a NUL character ('\\x00'), which no name or path holds.")
    return text


def _is_path(value):
    return isinstance(value, (str, bytes, os.PathLike))


def _path(value, argument):
    """A file's path as str: str, bytes (decoded as os.fsdecode does) or os.PathLike, as Python's open() takes."""
    if not _is_path(value):
        raise ArgumentTypeError(f"{argument} must be a file's path (str, bytes or os.PathLike), "
                                f"not {_type_name(value)}.")
    path = os.fspath(value)
    if not isinstance(path, (str, bytes)):
        raise ArgumentTypeError(f"{argument} must be a file's path, but its __fspath__ gave {_type_name(path)}.")
    path = _no_nul(os.fsdecode(path), argument)
    try:
        path.encode("utf-8")
    except UnicodeEncodeError:
        raise ValueError(f"{argument} {path!r} is not UTF-8 text; gyrocal takes paths in UTF-8.") from None
    return path


def _record(value, argument):
    """A record: its path (see _path), or a mapping of its columns (anything indexable by a column's name)."""
    if _is_path(value):
        return _path(value, argument)
    if not hasattr(value, "__getitem__"):
        raise ArgumentTypeError(f"{argument} must be a record's path or a mapping of its columns (a dict of "
                                f"arrays, a pandas DataFrame), not {_type_name(value)}.")
    return value


def _scenario(value, argument):
    if not isinstance(value, Scenario):
        raise ArgumentTypeError(f"{argument} must be a gyrocal.Scenario (gyrocal.Scenario.load(path), "
                                f"gyrocal.Scenario.parse(text) or gyrocal.Scenario()), not {_type_name(value)}.")
    return value


def _optional(check):
    """The check `check`, with None let through (an optional argument left out)."""
    return lambda value, argument: None if value is None else check(value, argument)


def _text(value, argument):
    if not isinstance(value, str):
        raise ArgumentTypeError(f"{argument} must be a str, not {_type_name(value)}.")
    return value


def _name(value, argument):
    return _no_nul(_text(value, argument), argument)


def _choice(default):
    """A choice given as text ("least-squares"); None is `default` (for the scenario's own choice, "")."""
    def check(value, argument):
        if value is None:
            return default
        if not isinstance(value, str):
            raise ArgumentTypeError(f"{argument} must be a string or None, not {_type_name(value)}.")
        return _no_nul(value, argument)
    return check


def _estimate(value, argument):
    """None (the scenario's [calibration] estimate), one name, or an iterable of names: a list of str."""
    if value is None:
        return None
    if isinstance(value, str):
        return [_no_nul(value, argument)]
    if isinstance(value, bytes) or not hasattr(value, "__iter__"):
        raise ArgumentTypeError(f"{argument} must be a machine error's name or a list of names, "
                                f"not {_type_name(value)}.")
    names = list(value)
    for name in names:
        if not isinstance(name, str):
            raise ArgumentTypeError(f"{argument} must be a list of names (str), but it holds {_type_name(name)} "
                                    f"{name!r}.")
        _no_nul(name, argument)
    return names


#: The largest seed: the simulation's seed is an unsigned 64-bit integer, as --seed.
_MAX_SEED = 2**64 - 1


def _seed(value, argument):
    """None (the scenario's [test] seed) or an integer from 0 to 2**64 - 1, Python's or NumPy's."""
    if value is None:
        return None
    try:
        seed = operator.index(value)
    except TypeError:
        raise ArgumentTypeError(f"{argument} must be an integer from 0 to {_MAX_SEED}, not {value!r}.") from None
    if not 0 <= seed <= _MAX_SEED:
        raise ValueError(f"{argument} must be an integer from 0 to {_MAX_SEED}, not {seed}.")
    return seed


def _is_real(value):
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))


def _real(value, argument):
    """A real number (Python's or NumPy's, or a 0-d array of one) as a float."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        return float(value)
    if not _is_real(value):
        raise ArgumentTypeError(f"{argument} must be a number, not {_type_name(value)}.")
    return float(value)


#: What an array of a kind that does not hold numbers holds, by NumPy's kind character.
_KIND_NAMES = {"U": "str", "S": "bytes", "b": "bool", "c": "complex", "M": "datetime64", "m": "timedelta64"}


def _numbers(value, what):
    """`value` (a number, a sequence or an array of numbers) as a contiguous float64 array. A value that is not a
    number (None, a str, a bool) is refused by name: NumPy would make None a NaN and "1.5" a number."""
    if value is None:
        raise ArgumentTypeError(f"{what} must be a number or an array of numbers, not None.")
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as e:
        raise ArgumentTypeError(f"{what} is not an array of numbers ({e}).") from None
    kind = array.dtype.kind
    if kind == "O":
        for item in array.flat:
            if not _is_real(item):
                raise ArgumentTypeError(f"{what} must hold numbers, not {_type_name(item)}.")
    elif kind not in "iuf":
        raise ArgumentTypeError(f"{what} must hold numbers, not {_KIND_NAMES.get(kind, array.dtype.name)}.")
    return np.ascontiguousarray(array, dtype=np.float64)


def _arguments(**checks):
    """Checks the named arguments of the decorated function, each with its check(value, name), which returns the
    value to use or raises; a call that does not bind (an unknown or missing argument) raises
    ArgumentTypeError in one sentence."""
    def decorate(function):
        signature = inspect.signature(function)

        @functools.wraps(function)
        def checked(*args, **kwargs):
            try:
                bound = signature.bind(*args, **kwargs)
            except TypeError as e:
                raise ArgumentTypeError(f"{function.__name__}(): {e}.") from None
            bound.apply_defaults()
            for name, check in checks.items():
                bound.arguments[name] = check(bound.arguments[name], name)
            return function(*bound.args, **bound.kwargs)
        return checked
    return decorate


# --- records ----------------------------------------------------------------------------------------------------

def _column(rec, name):
    try:
        values = rec[name]
    except (KeyError, IndexError, TypeError, ValueError):
        raise ValueError(f"{_ARRAYS_NAME}: the record has no column {name}.") from None
    return _numbers(values, f"{_ARRAYS_NAME}: column {name}")


#: gyrocal's own output columns: a gyro's (deg/h) and an accelerometer's (g).
_GYRO_COLUMN = "gyro_deg_h"
_ACCEL_COLUMN = "accel_g"


def _has_column(rec, name):
    try:
        rec[name]
    except (KeyError, IndexError, TypeError, ValueError):
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


@_arguments(scenario=_scenario, beta_deg=_real)
def exact_inputs(scenario, time_s, beta_deg):
    """Exact inputs to the gyro at the instants time_s (s) of a dwell at the scenario's rate and beta_deg,
    as `gyrocal inputs --time-s T --beta-deg B`: (omega, specific_force), each an (n, 3) float64 array of
    the I, O, S components, rad/s and g. time_s is a number or a one-dimensional array; an array of more
    dimensions, or a value that is not finite (as beta_deg), raises ValueError as the command line refuses
    it."""
    _gyrocal._refuse_imu(scenario, "gyrocal.exact_inputs")
    t = _numbers(time_s, "time_s")
    if t.ndim == 0:
        t = t.reshape(1)
    return _gyrocal._exact_inputs(scenario, t, beta_deg)


@_arguments(scenario=_scenario, seed=_seed)
def simulate(scenario, seed=None):
    """The record `gyrocal simulate --seed SEED` writes, held in memory: a dict of float64 arrays named as the
    record's columns (RECORD_COLUMNS; an accelerometer's output is keyed accel_g, in g, as its record's header). seed=None takes the scenario's [test] seed, as without --seed; any other
    seed is an integer from 0 to 2**64 - 1 (ValueError otherwise). An IMU's scenario gives its record as the
    command line writes it: time_s, the three angles and every channel's column in its own units (an increment as
    an increment), keyed as its header (imu_columns(sc)), which calibrate and noise take back."""
    return _gyrocal._simulate(scenario, seed)


@_arguments(rec=_record, scenario=_scenario, method=_choice("least-squares"), compensation=_choice("full"),
            estimate=_estimate, reduction=_choice(""), gyro_model=_choice(""))
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
    Kpp Koo delta_p delta_o), from a record whose output column is accel_g. method and compensation left None
    take their defaults, as the command line without --method and --compensation.

    An IMU's scenario ([sensor] kind = "imu", docs/imu.md) gives `gyrocal calibrate --json` of an IMU: "sensor"
    "imu" and "channels" keyed by the channels' names. Its mapping holds the columns its file would hold, in their
    own units (an increment as an increment): the time, the three angles and every channel's column, named as the
    scenario's [record] and [[channel]] tables name them (gyrocal.imu_columns(sc))."""
    options = (method, compensation, reduction, estimate, gyro_model)
    if scenario.sensor_kind == "imu":
        # Every channel's column in one pass and one joint solve, as `gyrocal calibrate` of an IMU.
        if isinstance(rec, str):
            return _gyrocal._calibrate_imu_path(rec, scenario, *options)
        names = _gyrocal._imu_columns(scenario, True)
        return _gyrocal._calibrate_imu_arrays([_column(rec, name) for name in names], names, scenario, *options,
                                              _ARRAYS_NAME)
    if isinstance(rec, str):
        return _gyrocal._calibrate_path(rec, scenario, *options)
    names = RECORD_COLUMNS[:4] + (_output_column(rec, scenario),)
    columns = [_column(rec, name) for name in names]
    return _gyrocal._calibrate_arrays(*columns, scenario, *options, _ARRAYS_NAME)


@_arguments(rec=_record, scenario=_optional(_scenario))
def noise(rec, scenario=None):
    """`gyrocal noise --json` as a dict: the overlapping Allan deviation of the record's output and the fitted
    IEEE 952 terms. rec is a record's path or a mapping of arrays holding time_s and the output: gyro_deg_h
    (a gyro's, deg/h) or accel_g (an accelerometer's, g; its terms keyed as [accelerometer.noise], in ug).
    A record's path is read through the scenario's [record] layout when it has one (as `gyrocal noise
    --config`), and the scenario's [sensor] kind says whose output it must hold; without a scenario the
    record's output column says. The noise itself does not depend on the scenario.

    An IMU's scenario gives `gyrocal noise --json` of an IMU: "sensor" "imu" and "channels" keyed by the channels'
    names, each a gyro's terms (deg/h) or an accelerometer's (ug). Its mapping holds the time and every channel's
    column as its file would (gyrocal.imu_columns(sc, angles=False)); angle columns are not read from a
    mapping."""
    if scenario is not None and scenario.sensor_kind == "imu":
        # Every channel's terms, each in its own sensor's unit, as `gyrocal noise --config` of an IMU.
        if isinstance(rec, str):
            return _gyrocal._noise_imu_path(rec, scenario)
        names = _gyrocal._imu_columns(scenario, False)
        return _gyrocal._noise_imu_arrays([_column(rec, name) for name in names], names, scenario, _ARRAYS_NAME)
    if isinstance(rec, str):
        return _gyrocal._noise_path(rec, scenario)
    if scenario is not None:
        column = _output_column(rec, scenario)
    else:
        column = _ACCEL_COLUMN if _has_column(rec, _ACCEL_COLUMN) and not _has_column(rec, _GYRO_COLUMN) \
            else _GYRO_COLUMN
    return _gyrocal._noise_arrays(_column(rec, "time_s"), _column(rec, column), column, _ARRAYS_NAME)


@_arguments(scenario=_scenario)
def imu_columns(scenario, angles=True):
    """The columns an IMU's record is read with, as a tuple of names in order: the time, the three angle columns
    (with angles=True: what calibrate needs; noise needs none), then every channel's column, as the scenario's
    [record] and [[channel]] tables name them. A mapping given to calibrate or noise for an IMU holds these
    columns in their own units, as the record's file does. A lone sensor's scenario raises ValueError."""
    if not isinstance(angles, (bool, np.bool_)):
        raise ArgumentTypeError(f"angles must be True or False, not {_type_name(angles)}.")
    return tuple(_gyrocal._imu_columns(scenario, bool(angles)))


@_arguments(db=_path, unit=_name)
def history(db, unit):
    """`gyrocal history show --unit UNIT --db DB --json` as a dict: the unit, its sensor, its runs
    ([{id, date, record_sha256, note, date_source, gyrocal_version, flags}]), and per channel's coefficient
    (d["channels"][CHANNEL][COEFFICIENT]) and per machine error of the rig (d["machine_errors"][ERROR]) an
    entry with the runs' values and their repeatability (mean, run_to_run_std, f_test_p, trend_per_day, limits,
    flagged, ...; docs/history.md). Each entry also holds its runs as arrays, in date order: "values" and "stds"
    (float64, in the entry's "unit"), "days" (float64, days since 1970-01-01 UTC:
    pandas.to_datetime(e["days"], unit="D")) and "run_ids" (int64). The database (a path) is opened read-only
    and never created; a missing database, one that is not a gyrocal history, or a unit it does not hold
    (the sentence lists the units it has) raises ValueError with the command line's sentence."""
    return _gyrocal._history(db, unit)


# --- Scenario.load and Scenario.parse: the compiled class's, with their arguments checked as above -------------

@_arguments(path=_path)
def _load(path):
    """Read the configuration file (TOML) at path (str, bytes or os.PathLike), as --config does."""
    return Scenario._load(path)


@_arguments(text=_text, name=_name)
def _parse(text, name="<string>"):
    """Parse a configuration given as TOML text; name stands for the file in messages. Text that is empty or
    white space only, or larger than 1 MiB, is refused as a configuration file is."""
    return Scenario._parse(text, name)


Scenario.load = staticmethod(_load)
Scenario.parse = staticmethod(_parse)
