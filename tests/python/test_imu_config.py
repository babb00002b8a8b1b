"""A whole IMU's configuration from Python (issue 27; docs/imu.md): it loads, and every function that does not
serve an IMU yet refuses it with the command line's sentence (simulate, calibrate and noise serve one: test_imu.py).

ctest runs this file as test_gyrocal.py is run (tests/CMakeLists.txt): PYTHONPATH=<build>/python and GYROCAL_CLI
set to the command line's executable.
"""

import pytest

import gyrocal

IMU = """[sensor]
kind = "imu"

[[channel]]
name = "gx"
sensor = "gyro"
input_axis = "+x"
second_axis = "+y"
"""

TAIL = ('does not serve an IMU configuration yet ([sensor] kind = "imu"); docs/imu.md, "What serves an IMU", '
        'lists the commands that do.')


def test_an_imu_configuration_loads():
    assert gyrocal.Scenario.parse(IMU).sensor_kind == "imu"
    assert gyrocal.Scenario().sensor_kind == "gyro"


@pytest.mark.parametrize("name,call", [
    ("exact_inputs", lambda sc: gyrocal.exact_inputs(sc, time_s=0.0, beta_deg=0.0)),
])
def test_functions_that_do_not_serve_an_imu_refuse_it(name, call):
    with pytest.raises(ValueError) as refusal:
        call(gyrocal.Scenario.parse(IMU))
    assert str(refusal.value) == f"gyrocal.{name} {TAIL}"
