"""The base station and the carrier phase on a drive: the phase adds up from its truth terms
(with the integer ambiguity), every blockage starts new arcs, the base shares the rover's sky
so that its double-differenced ionosphere grows with the baseline, and a base without a rover
or at a rate that does not divide the rover's is refused."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from simulator.dataset.generate import generate_streams
from simulator.errors import InputError
from simulator.gnss.carrier import LLI_LOST_LOCK
from simulator.gnss.constants import C_M_S
from tests.conftest import scenario_data

TUNNEL_DRIVE = [{"stop": {"duration": 30}}, {"accelerate": {"to_speed": 15.0, "accel": 1.5}},
                {"straight": {"length": 600}}, {"straight": {"length": 300, "zone": "tunnel"}},
                {"straight": {"length": 600}}]


@pytest.fixture(scope="module")
def tunnel_drive():
    data = scenario_data(TUNNEL_DRIVE, environment={"zones": {"tunnel": {"sky": "none"}}},
                         sensors={"gnss": {"preset": "dual-band", "rate": 2,
                                           "outputs": ["raw"]},
                                  "gnss_base": {"offset": {"east": 3000.0}, "rate": 1}})
    return generate_streams(data, show_progress=False)


def test_carrier_phase_adds_up_from_its_truth_terms(tunnel_drive):
    """lambda Phi = range + receiver_clock - (sat_clock + group_delay) - iono_true + tropo_true
    + sis_error + carrier_multipath + nlos_delay + phase_noise + lambda (ambiguity + half_cycle),
    the ambiguity an integer, for rover and base."""
    for raw_name, truth_name in (("gnss_raw", "truth_gnss"), ("gnss_base_raw", "truth_gnss_base")):
        raw = tunnel_drive.streams[raw_name]
        truth = tunnel_drive.streams[truth_name]
        m = raw.merge(truth, on=["t", "sv", "signal"], suffixes=("", "_truth"))
        assert len(m) == len(raw) > 1000
        lam = C_M_S / m["frequency"]
        rebuilt = (m["range"] + m["receiver_clock"] - (m["sat_clock"] + m["group_delay"])
                   - m["iono_true"] + m["tropo_true"] + m["sis_error"] + m["carrier_multipath"]
                   + m["nlos_delay"] + m["phase_noise"]) / lam + m["ambiguity"] + m["half_cycle"]
        np.testing.assert_allclose(m["carrier_phase"], rebuilt, rtol=0, atol=1e-5)
        assert (m["ambiguity"] == np.round(m["ambiguity"])).all()


def test_every_signal_starts_a_new_arc_after_the_tunnel(tunnel_drive):
    raw = tunnel_drive.streams["gnss_raw"]
    events = tunnel_drive.streams["events"]
    tunnel = events[events["kind"] == "gnss_outage"].iloc[0]
    after = raw[raw["t"] >= tunnel["t_end"]]
    first = after[after["t"] == after["t"].min()]
    assert len(first) >= 8 and set(first["signal"]) == {"1C", "2L"}
    assert (first["lli"] & LLI_LOST_LOCK).all() and (first["lock_time"] == 0).all()
    truth = tunnel_drive.streams["truth_gnss"]
    before = truth[(truth["t"] < tunnel["t_start"]) & (truth["tracked"] == 1)]
    later = truth[(truth["t"] >= tunnel["t_end"]) & (truth["tracked"] == 1)]
    # the arcs after the tunnel are new ones, with their own ambiguities
    assert not set(later["arc"]) & set(before["arc"])


def _dd_iono_rms(offset_east_m: float) -> float:
    data = scenario_data([{"stop": {"duration": 1800}}],
                         sensors={"gnss": {"preset": "geodetic", "rate": 1 / 30,
                                           "outputs": ["raw"], "signals": {"gps": ["1C"]}},
                                  "gnss_base": {"offset": {"east": offset_east_m},
                                                "rate": 1 / 30, "signals": {"gps": ["1C"]}}})
    streams = generate_streams(data, show_progress=False).streams
    cols = ["t", "sv", "iono_true", "elevation", "tracked"]
    m = streams["truth_gnss"][cols].merge(streams["truth_gnss_base"][cols], on=["t", "sv"],
                                          suffixes=("_r", "_b"))
    m = m[(m["tracked_r"] == 1) & (m["tracked_b"] == 1)]
    m = m.assign(sd=m["iono_true_r"] - m["iono_true_b"])
    ref = m.loc[m.groupby("t")["elevation_r"].idxmax(), ["t", "sd"]]
    dd = m.merge(ref, on="t", suffixes=("", "_ref"))
    dd = dd[dd["sd"] != dd["sd_ref"]]
    return float(np.sqrt(np.mean((dd["sd"] - dd["sd_ref"]) ** 2)))


def test_double_differenced_ionosphere_grows_with_the_baseline():
    """The base sees the ionosphere at its own pierce points: the double-differenced L1
    ionosphere (reference: the highest satellite) grows in proportion to the baseline, by a few
    millimetres to centimetres per 10 km as on a quiet mid-latitude day (docs/gnss-carrier.md:
    the travelling disturbances' 0.5 mm/km, the regional field's and the model's own
    gradients)."""
    rms = {d: _dd_iono_rms(d) for d in (2500.0, 10000.0, 40000.0)}
    print("\nDD ionosphere rms by baseline:", {k / 1e3: round(1e3 * v, 1) for k, v in rms.items()},
          "mm")
    assert 0.002 < rms[10000.0] < 0.03
    assert 3.0 < rms[10000.0] / rms[2500.0] < 5.0
    assert 3.0 < rms[40000.0] / rms[10000.0] < 5.0


@pytest.mark.parametrize(("sensors", "message"), [
    ({"gnss_base": {"offset": {"east": 10.0}}}, "needs sensors.gnss"),
    ({"gnss": {"rate": 1}, "gnss_base": {"offset": {"east": 10.0}, "rate": 0.3}},
     "whole multiple"),
    ({"gnss": {"rate": 1}, "gnss_base": {}}, "exactly one of position and offset"),
    ({"gnss": {"rate": 1, "signals": {"gps": ["9X"]}}}, "signal codes"),
])
def test_bad_base_or_signal_blocks_are_refused(sensors, message):
    with pytest.raises(InputError, match=message):
        scenario_data([{"stop": {"duration": 10}}], sensors=sensors)


def test_chunks_and_satellite_groups_change_no_number(monkeypatch):
    """The measurements computed a few epochs at a time (``simulator.gnss.chunks``: chunks of
    37 epochs, the carrier smoothing in groups of 500 samples, the fixes' accuracy 29 epochs
    at a time) are, bit for bit, those of one pass over the whole drive: rover (through a
    canyon and a tunnel), base and fixes, four systems on two frequencies, carrier phase."""
    from simulator.gnss import chunks, errors, fix

    data = scenario_data(
        [{"stop": {"duration": 10}}, {"accelerate": {"to_speed": 12.0, "accel": 1.5}},
         {"straight": {"length": 300, "zone": "street"}},
         {"straight": {"length": 150, "zone": "tunnel"}}, {"straight": {"length": 200}}],
        environment={"zones": {"street": {"sky": "canyon"}, "tunnel": {"sky": "none"}}},
        sensors={"gnss": {"preset": "dual-band", "rate": 2, "outputs": ["raw", "fix"],
                          "systems": ["gps", "galileo", "beidou", "glonass"]},
                 "gnss_base": {"offset": {"east": 2000.0}, "rate": 2, "preset": "dual-band",
                               "systems": ["gps", "galileo", "beidou", "glonass"]}})
    monkeypatch.setattr(chunks, "CHUNK_EPOCHS", 37)
    monkeypatch.setattr(errors, "SMOOTHING_GROUP_SAMPLES", 500)
    monkeypatch.setattr(fix, "FIX_CHUNK_EPOCHS", 29)
    small = generate_streams(data, show_progress=False).streams
    monkeypatch.setattr(chunks, "CHUNK_EPOCHS", 10**9)
    monkeypatch.setattr(errors, "SMOOTHING_GROUP_SAMPLES", 10**12)
    monkeypatch.setattr(fix, "FIX_CHUNK_EPOCHS", 10**9)
    whole = generate_streams(data, show_progress=False).streams
    names = ("gnss_raw", "truth_gnss", "gnss_fix", "gnss_base_raw", "truth_gnss_base")
    for name in names:
        pd.testing.assert_frame_equal(small[name], whole[name], check_exact=True)
    raw = small["gnss_raw"]
    assert len(small["gnss_fix"]) > 2 * 37 and set(raw["system"]) == {"G", "E", "C", "R"}
    assert (raw["lli"] > 0).any() and len(small["gnss_base_raw"]) > 1000
