"""The GNSS receiver's random streams (layout in ``simulator.sensors.gnss_observables``): a
named child stream depends only on its parent's seed and its name; the same scenario and seed
give identical streams (rover, base, canyon, carrier phase); a process that draws a different
number of values (here the C/N0 fading, switched off) redraws none of the drive-long errors
(receiver clock, signal-in-space error, ionosphere, troposphere) of rover or base."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from simulator.dataset.generate import generate_streams
from simulator.stochastic import child_rng, stream_rng
from tests.conftest import scenario_data

CANYON_DRIVE = [{"stop": {"duration": 5}}, {"accelerate": {"to_speed": 10.0, "accel": 2.0}},
                {"straight": {"length": 150, "zone": "canyon"}}, {"straight": {"length": 100}}]


def _streams(**gnss) -> dict[str, pd.DataFrame]:
    data = scenario_data(
        CANYON_DRIVE, environment={"zones": {"canyon": {"sky": "canyon"}}},
        sensors={"gnss": {"preset": "dual-band", "rate": 2, "outputs": ["raw"], **gnss},
                 "gnss_base": {"offset": {"east": 2000.0}, "rate": 1}})
    return generate_streams(data, show_progress=False).streams


@pytest.fixture(scope="module")
def first():
    return _streams()


def test_a_child_stream_depends_only_on_the_seed_and_its_name():
    parent = stream_rng(1, "gnss")
    before = child_rng(parent, "receiver_clock").standard_normal(4)
    parent.standard_normal(1000)
    child_rng(parent, "sis").standard_normal(1000)
    np.testing.assert_array_equal(child_rng(parent, "receiver_clock").standard_normal(4), before)
    assert not np.any(child_rng(parent, "sis").standard_normal(4) == before)
    assert not np.any(child_rng(stream_rng(2, "gnss"), "receiver_clock").standard_normal(4)
                      == before)
    assert type(child_rng(parent, "sis").bit_generator) is type(parent.bit_generator)


def test_same_seed_gives_identical_streams(first):
    again = _streams()
    assert {"gnss_raw", "truth_gnss", "gnss_base_raw", "truth_gnss_base"} <= set(first)
    assert (first["truth_gnss"]["nlos"] == 1).any()  # the canyon's draws are in play
    for name, frame in first.items():
        pd.testing.assert_frame_equal(again[name], frame, check_exact=True, obj=name)


def test_fewer_fading_draws_redraw_no_drive_long_error(first):
    """Without C/N0 fading the receiver draws no fading process (n_sat x n_epoch values fewer);
    the clock, broadcast errors and atmosphere of rover and base are the same to the bit, the
    C/N0 (which the fading is part of) is not."""
    unfaded = _streams(cn0_fading=0.0)
    for name in ("truth_gnss", "truth_gnss_base"):
        a, b = first[name], unfaded[name]
        assert len(a) == len(b) > 100  # one row per satellite above the horizon and epoch
        for column in ("receiver_clock", "receiver_clock_drift", "sis_error", "iono_true",
                       "tropo_true", "range"):
            np.testing.assert_array_equal(a[column], b[column], err_msg=f"{name}.{column}")
    cn0 = first["gnss_raw"].merge(unfaded["gnss_raw"], on=["t", "sv", "signal"])
    assert not np.allclose(cn0["cn0_x"], cn0["cn0_y"])


def test_rows_in_epoch_satellite_signal_order_as_pandas_sorts_them():
    """Each signal's (satellite, epoch) samples become one table in the order of epochs, then
    satellites, then the receiver's signals, each value in its row, as pandas' stable sort of
    the signals' rows has them (the table's counting rank against a sort), whether a signal's
    epochs come at once or in chunks; the frame takes the table's columns (the rows are not
    held twice)."""
    from simulator.sensors.gnss_observables import _Table

    rng = np.random.default_rng(3)
    t, svs = np.arange(7) * 0.5, np.array([3, 5, 8, 11, 12])
    # (system's satellites, text) per signal in the receiver's order: two systems, one with
    # two signals
    signals = [(np.array([0, 2, 3]), "1C"), (np.array([0, 2, 3]), "2L"), (np.array([1, 4]), "1C")]
    masks = [rng.random((len(sel), len(t))) < 0.6 for sel, _ in signals]
    values = [rng.standard_normal((len(sel), len(t))) for sel, _ in signals]
    per_satellite = [rng.integers(0, 9, (len(sel), 1)) for sel, _ in signals]
    table = _Table(t, svs, [(sel, m) for (sel, _), m in zip(signals, masks, strict=True)])
    expected = []
    for order, ((sel, text), mask, x, k) in enumerate(
            zip(signals, masks, values, per_satellite, strict=True)):
        for cols in (slice(0, 4), slice(4, 7)):  # in two chunks of epochs
            table.add(sel, mask[:, cols], {"x": x[:, cols], "k": k, "signal": text}, cols.start)
        sat, ep = np.nonzero(mask)
        expected.append(pd.DataFrame({"t": t[ep], "sv": svs[sel[sat]], "x": x[sat, ep],
                                      "k": k[sat, 0], "signal": text, "_row": sel[sat],
                                      "_order": order}))
    want = (pd.concat(expected, ignore_index=True)
            .sort_values(["t", "_row", "_order"], kind="stable")
            .drop(columns=["_row", "_order"]).reset_index(drop=True))
    got = table.frame(["t", "sv", "x", "k", "signal"])
    pd.testing.assert_frame_equal(got, want, check_dtype=False)
    assert not table.columns
