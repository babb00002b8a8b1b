"""gyrocal.history(db, unit) is `gyrocal history show --json` as a dict, with each quantity's runs also as numpy
arrays; its errors are ValueErrors with the command line's sentence (issue 30; docs/python.md).

The database is built with the command line: three small records of different seeds simulated, calibrated and
stored with `history add`. Every expected value comes from the command line's JSON read back with json.loads.
"""

import json
import math
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

DATES = ("2026-01-05", "2026-01-12", "2026-02-02")


def run_cli(*args, check=True, cwd=None):
    proc = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, cwd=cwd)
    if check:
        assert proc.returncode == 0, proc.stderr
    return proc


def cli_error(*args, cwd=None):
    """The command line's error sentence: its standard error without the 'gyrocal: ' prefix."""
    proc = run_cli(*args, check=False, cwd=cwd)
    assert proc.returncode == 1, (proc.returncode, proc.stdout, proc.stderr)
    assert proc.stderr.startswith("gyrocal: ")
    return proc.stderr[len("gyrocal: "):].rstrip("\n")


@pytest.fixture(scope="module")
def database(tmp_path_factory):
    folder = tmp_path_factory.mktemp("history")
    config = folder / "small.toml"
    config.write_text(SMALL_TEST)
    db = folder / "lab.sqlite"
    for k, date in enumerate(DATES, start=1):
        record, result = folder / f"r{k}.csv", folder / f"r{k}.json"
        run_cli("simulate", "--config", config, "--seed", k, "--out", record)
        run_cli("calibrate", record, "--config", config, "--estimate", "main_wobble_x:1", "--json", result)
        run_cli("history", "add", result, "--unit", "SN-7", "--db", db, "--date", date, "--note", f"run {k}")
    return db


def without_arrays(entry):
    return {k: v for k, v in entry.items() if k not in ("values", "stds", "days", "run_ids")}


def test_history_is_shows_json_with_arrays(database):
    cli = json.loads(run_cli("history", "show", "--unit", "SN-7", "--db", database, "--json", "-").stdout)
    cli.pop("gyrocal")  # the file's marker, which only a file carries
    h = gyrocal.history(str(database), "SN-7")
    # Every key and number as the command line's, the arrays aside.
    py = dict(h)
    py["channels"] = {c: {n: without_arrays(e) for n, e in coefs.items()} for c, coefs in h["channels"].items()}
    py["machine_errors"] = {n: without_arrays(e) for n, e in h["machine_errors"].items()}
    assert py == cli
    assert [r["note"] for r in h["runs"]] == ["run 1", "run 2", "run 3"]
    entries = list(h["channels"]["gyro"].values()) + list(h["machine_errors"].values())
    assert len(h["channels"]["gyro"]) >= 10 and "main_wobble_x:1:sin" in h["machine_errors"]
    for entry in entries:
        runs = entry["runs"]
        for key, field, dtype in (("values", "value", np.float64), ("stds", "std", np.float64),
                                  ("run_ids", "id", np.int64)):
            assert isinstance(entry[key], np.ndarray) and entry[key].dtype == dtype
            assert entry[key].tolist() == [r[field] for r in runs]
        # Days since 1970-01-01 UTC of each run's date.
        epoch = np.datetime64("1970-01-01")
        expected = [(np.datetime64(r["date"][:10]) - epoch) / np.timedelta64(1, "D") for r in runs]
        assert entry["days"].dtype == np.float64 and entry["days"].tolist() == expected
        for key in ("mean", "run_to_run_std", "f_test_p"):
            assert entry[key] is None or isinstance(entry[key], float)
    stated = [e for e in h["channels"]["gyro"].values() if len(e["runs"]) == len(DATES)]
    assert stated, "no coefficient stated by every run"
    for e in stated:
        # The weighted mean and the run-to-run std from the arrays, as a numpy user would compute them.
        w = 1 / e["stds"] ** 2
        assert math.isclose(e["mean"], float(np.sum(w * e["values"]) / np.sum(w)), rel_tol=1e-12)
        assert math.isclose(e["run_to_run_std"], float(np.std(e["values"], ddof=1)), rel_tol=1e-9)


def test_pandas_takes_the_arrays(database):
    pd = pytest.importorskip("pandas")
    e = gyrocal.history(database, "SN-7")["channels"]["gyro"]["dI"]  # identified by the short test's plan
    frame = pd.DataFrame({"date": pd.to_datetime(e["days"], unit="D"), "value": e["values"], "std": e["stds"]},
                         index=e["run_ids"])
    assert [d.strftime("%Y-%m-%d") for d in frame["date"]] == list(DATES)


def test_errors_are_the_command_lines(database, tmp_path):
    unknown = cli_error("history", "show", "--unit", "SN-8", "--db", database)
    with pytest.raises(ValueError) as e:
        gyrocal.history(database, "SN-8")
    assert str(e.value) == unknown
    assert "SN-7" in unknown
    missing = tmp_path / "none.sqlite"
    with pytest.raises(ValueError) as e:
        gyrocal.history(missing, "SN-7")
    assert str(e.value) == cli_error("history", "show", "--unit", "SN-7", "--db", missing)
    assert not missing.exists()
    with pytest.raises(TypeError):
        gyrocal.history(database, 7)
    with pytest.raises(TypeError):
        gyrocal.history(None, "SN-7")
