"""The ``sensors.gnss`` scenario block: presets, validation messages, and the constellation
sources (nominal, RINEX navigation file, YUMA almanac; a file that does not cover the drive)."""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np
import pytest
from gnss_helpers import drive, receiver

from simulator.errors import InputError
from simulator.schema import Context
from simulator.sensors import SENSOR_FIELDS, SENSOR_MODELS
from simulator.sensors.gnss import GNSS_FIELD, PRESETS, Gnss

ALMANAC = Path(__file__).resolve().parents[3] / "shared" / "refdata" / "almanac" / \
    "maast_2020-01-01" / "almyuma_01jan2020.txt"


def _problems(config: dict) -> list[str]:
    ctx = Context("scenario.yaml")
    GNSS_FIELD.check(config, ("sensors", "gnss"), ctx)
    return [f"{p.key_path}: {p.message}" for p in ctx.problems]


def test_registered_and_defaults_filled_from_the_preset():
    assert SENSOR_FIELDS["gnss"] is GNSS_FIELD and SENSOR_MODELS["gnss"] is Gnss
    ctx = Context("scenario.yaml")
    value = GNSS_FIELD.check({"multipath": "50 cm"}, ("sensors", "gnss"), ctx)
    assert not ctx.problems
    assert value["multipath"] == pytest.approx(0.5)  # unit strings converted to SI
    assert value["clock"] == "tcxo" and value["outputs"] == ["fix", "raw"]
    for key, preset_value in PRESETS["automotive"].items():
        if key != "multipath":
            assert value[key] == preset_value
    ideal = GNSS_FIELD.check({"preset": "ideal"}, ("sensors", "gnss"), ctx)
    assert ideal["tracking_noise"] == 0 and ideal["clock"] == "ideal"


@pytest.mark.parametrize("config, fragment", [
    ({"preset": "survey"}, "sensors.gnss.preset: unknown GNSS preset 'survey'"),
    ({"clock": "rubidium"}, "sensors.gnss.clock: unknown oscillator 'rubidium'"),
    ({"constellation": "no/such/file.nav"}, "sensors.gnss.constellation: 'no/such/file.nav' is "
                                            "neither 'gps-almanac', 'nominal-gps' nor an existing"),
    ({"elevation_mask": 95}, "sensors.gnss.elevation_mask"),
    ({"outputs": ["position"]}, "sensors.gnss.outputs.0"),
    ({"multipath": "3 s"}, "sensors.gnss.multipath"),
    ({"cn0_horizon": 50}, "sensors.gnss.cn0_horizon: must not exceed cn0_zenith"),
    ({"rate": 1, "antena_lever_arm": [0, 0, 0]}, "sensors.gnss.antena_lever_arm"),
    ({"expanded_slots": ["B2"]}, "sensors.gnss.expanded_slots.0: 'B2' is not one of: B1, D2, F2"),
    ({"expanded_slots": ["B1", "B1"]}, "sensors.gnss.expanded_slots: names a slot more than once"),
    ({"constellation": __file__, "expanded_slots": ["B1"]},
     "sensors.gnss.expanded_slots: only applies to constellation 'nominal-gps'"),
])
def test_bad_configuration_is_reported_with_its_key(config, fragment):
    problems = _problems(config)
    assert any(fragment in p for p in problems), problems


def test_expanded_slots_add_their_aft_satellites_to_the_receiver():
    truth = drive([{"stop": {"duration": 600}}], rate_hz=1.0)
    rng = np.random.default_rng(3)
    # the 24-slot constellation is named: the default sky is the real almanac's
    base = receiver(preset="ideal", constellation="nominal-gps").generate(truth, rng)
    full = receiver(preset="ideal", constellation="nominal-gps",
                    expanded_slots=["B1", "D2", "F2"]).generate(truth, rng)
    assert set(base["gnss_nav"]["sv"]) == set(range(1, 25))
    assert set(full["gnss_nav"]["sv"]) == set(range(1, 28))
    n_base, n_full = base["gnss_fix"]["num_sats"], full["gnss_fix"]["num_sats"]
    assert (n_full >= n_base).all() and n_full.sum() > n_base.sum()
    assert (full["gnss_fix"]["fix"] == 2).all()
    k = truth.inertial(full["gnss_fix"]["t"].to_numpy())
    assert np.abs(full["gnss_fix"]["alt"] - k["alt"]).max() < 0.01


def test_yuma_almanac_as_constellation():
    if not ALMANAC.exists():
        pytest.skip(f"reference data {ALMANAC} not available (needs the shared/ folder)")
    truth = drive([{"stop": {"duration": 30}}], rate_hz=1.0, utc=dt.datetime(2020, 1, 3, 12))
    out = receiver(preset="ideal", constellation=str(ALMANAC)).generate(
        truth, np.random.default_rng(1))
    fix = out["gnss_fix"]
    assert (fix["fix"] == 2).all() and (fix["num_sats"] >= 6).all()
    k = truth.inertial(fix["t"].to_numpy())
    assert np.abs(fix["alt"] - k["alt"]).max() < 0.01
    assert set(out["gnss_nav"]["toe"]) == {503808.0}  # the almanac's time of applicability


def test_navigation_file_not_covering_the_drive_is_an_input_error():
    if not ALMANAC.exists():
        pytest.skip(f"reference data {ALMANAC} not available (needs the shared/ folder)")
    truth = drive([{"stop": {"duration": 30}}], rate_hz=1.0, utc=dt.datetime(2024, 5, 1))
    with pytest.raises(InputError, match="sensors.gnss.constellation: fewer than four"):
        receiver(constellation=str(ALMANAC)).generate(truth, np.random.default_rng(1))
