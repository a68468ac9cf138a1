"""``landnav estimators NAME``: an estimator's paper, streams and every config key with its
default, unit and meaning; every built-in describes each of its keys."""

from __future__ import annotations

import pytest

from estimators.registry import BUILTINS, get_estimator
from simulator.cli import main
from simulator.units import to_si


@pytest.mark.parametrize("name", list(BUILTINS))
def test_every_builtin_describes_each_config_key(name):
    cls = get_estimator(name)
    assert set(cls.config_help) == set(cls.defaults)
    for key, (unit, meaning) in cls.config_help.items():
        assert meaning, key
        if unit:
            assert to_si(f"1 {unit}", unit) == pytest.approx(1.0), (key, unit)  # pint reads it


def test_estimators_name_shows_paper_streams_and_config(capsys):
    assert main(["estimators", "dr2d_odo_ekf"]) == 0
    out = capsys.readouterr().out
    assert "Park et al. 2019" in out and "needs:   imu, odometer, gnss_fix" in out
    row = next(line for line in out.splitlines() if line.strip().startswith("gyro_bias_initial"))
    # Park et al. 2019, Table 1: the SMI130's 1 deg/s zero-point offset, stored in rad/s
    assert "0.0174533 rad/s = 1 deg/s" in row and "initial gyro-bias uncertainty" in row


def test_estimators_name_of_a_plugin_class(capsys):
    assert main(["estimators", "examples.my_estimator:MyEstimator"]) == 0
    out = capsys.readouterr().out
    assert "bias_sigma0" in out and "0.02 rad/s = 1.15 deg/s" in out


def test_estimators_unknown_name(capsys):
    assert main(["estimators", "kalmann"]) == 2
    err = capsys.readouterr().err
    assert "unknown estimator 'kalmann'" in err and "Traceback" not in err
