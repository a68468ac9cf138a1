"""Carrier phase: the PLL jitter and Viterbi's mean time to slip against their textbook forms,
the arcs, ambiguities, half cycles, LLI and lock time on hand-made tracking masks, and on a
static hour the code-minus-carrier divergence (twice the ionosphere) and the geometry-free phase
(the true differential ionosphere within millimetres)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import i0

from simulator.gnss.carrier import (
    LLI_HALF_CYCLE,
    LLI_LOST_LOCK,
    phase_arcs,
    pll_sigma_cycles,
    slip_probability,
)
from simulator.gnss.constants import C_M_S
from simulator.gnss.signals import carrier_frequency_hz, group_delay_factor, iono_factor
from tests.conftest import scenario_data


def test_pll_jitter_is_kaplan_hegartys_in_degrees():
    """sigma_tPLL = (360 / 2 pi) sqrt(B_n / (C/N0) (1 + 1 / (2 T C/N0))) degrees: 45 dB-Hz,
    10 Hz, 20 ms gives 1.02 deg (hand computation: 10 / 31623 = 3.162e-4, x 1.00079)."""
    sigma_deg = 360.0 * pll_sigma_cycles(45.0, 10.0, 0.02)
    assert sigma_deg == pytest.approx(360 / (2 * np.pi) * np.sqrt(3.16228e-4 * 1.000791),
                                      rel=1e-4)
    assert sigma_deg == pytest.approx(1.019, abs=0.001)


@pytest.mark.parametrize("rho", [2.0, 5.0, 20.0])
def test_slip_probability_is_viterbis_mean_time_to_slip(rho):
    """p = 1 - exp(-dt / T), T = pi^2 rho I0(rho)^2 / (2 B) (Viterbi 1966), evaluated here with
    I0 itself (the model works in logs); a Costas loop has rho / 4."""
    bandwidth, dt = 10.0, 1.0
    sigma_cycles = 1.0 / np.sqrt(rho) / (2 * np.pi)
    for pilot, loop_rho in ((True, rho), (False, rho / 4)):
        mean_time = np.pi**2 * loop_rho * i0(loop_rho) ** 2 / (2 * bandwidth)
        expected = 1.0 - np.exp(-dt / mean_time)
        got = slip_probability(np.array(sigma_cycles), np.array(0.0), bandwidth, dt, pilot)
        assert got == pytest.approx(expected, rel=1e-9)
    strong = slip_probability(np.array(pll_sigma_cycles(45.0, 10.0, 0.02)), np.array(0.0),
                              10.0, 1.0, False)
    assert strong == 0.0  # a strong signal never slips within a second


def test_arcs_ambiguities_slips_half_cycles_and_lli():
    tracked = np.array([[True] * 4 + [False] * 2 + [True] * 6])
    slips = np.zeros_like(tracked)
    slips[0, 9] = True
    lost = np.zeros_like(tracked)
    arcs = phase_arcs(np.random.default_rng(1), tracked, slips, lost, dt_s=1.0, pilot=False,
                      frame_s=6.0)
    # three arcs: epochs 0-3, 6-8 (after the gap), 9-11 (after the slip)
    assert list(arcs.arc[0]) == [0, 0, 0, 0, -1, -1, 1, 1, 1, 2, 2, 2]
    n = arcs.ambiguity[0]
    assert n[9] - n[8] == arcs.cycle_slip[0, 9] != 0
    assert arcs.cycle_slip[0].sum() == arcs.cycle_slip[0, 9]
    assert list(arcs.lock_time[0]) == [0, 1, 2, 3, 0, 0, 0, 1, 2, 0, 1, 2]
    assert all(arcs.lli[0, [0, 6, 9]] & LLI_LOST_LOCK)
    assert not any(arcs.lli[0, [1, 2, 3, 7, 8, 10, 11]] & LLI_LOST_LOCK)
    # the half cycle: 0 or 0.5, present only while the LLI's half-cycle bit is set
    half_bit = (arcs.lli[0] & LLI_HALF_CYCLE) > 0
    assert set(np.unique(arcs.half)) <= {0.0, 0.5}
    assert not np.any(arcs.half[0][~half_bit])
    pilot = phase_arcs(np.random.default_rng(1), tracked, slips, lost, 1.0, True, 0.0)
    assert not np.any(pilot.lli & LLI_HALF_CYCLE) and not np.any(pilot.half)


def test_group_delay_and_ionosphere_scale_by_frequency():
    """IS-GPS-200: L2 P(Y) carries gamma T_GD, gamma = (1575.42 / 1227.60)^2 = 1.6469."""
    assert group_delay_factor("G", "2W") == pytest.approx((77 / 60) ** 2)
    assert group_delay_factor("G", "1C") == 1.0
    f2 = float(carrier_frequency_hz("G", "2W"))
    assert f2 == 1227.6e6
    assert float(iono_factor(f2)) == pytest.approx(1.6469, abs=1e-4)
    assert float(carrier_frequency_hz("R", "1C", 1)) == 1602.5625e6


@pytest.fixture(scope="module")
def static_hour():
    """An hour standing still with the geodetic preset on GPS L1/L2 at 1 Hz."""
    from simulator.dataset.generate import generate_streams

    data = scenario_data([{"stop": {"duration": 3600}}],
                         sensors={"gnss": {"preset": "geodetic", "rate": 1, "outputs": ["raw"],
                                           "constellation": "nominal-gps",
                                           "signals": {"gps": ["1C", "2W"]}}})
    streams = generate_streams(data, show_progress=False).streams
    return streams["gnss_raw"], streams["truth_gnss"]


def _long_arcs(raw, truth, signal):
    rows = raw[raw["signal"] == signal].merge(
        truth[truth["signal"] == signal][["t", "sv", "arc", "iono_true", "multipath"]],
        on=["t", "sv"])
    sizes = rows.groupby(["sv", "arc"])["t"].transform("size")
    return rows[sizes >= 1800]


def test_code_minus_carrier_diverges_at_twice_the_ionosphere(static_hour):
    """P - lambda Phi = 2 I + (ambiguity) + code noise and multipath: regressed on the true
    ionosphere over each arc of at least 30 min, the coefficient is 2 (the code delayed and
    the phase advanced by the same 40.3 TEC / f^2)."""
    raw, truth = static_hour
    rows = _long_arcs(raw, truth, "1C")
    lam = C_M_S / rows["frequency"]
    rows = rows.assign(cmc=rows["pseudorange"] - lam * rows["carrier_phase"])
    slopes, spans = [], []
    for _, arc in rows.groupby(["sv", "arc"]):  # one regression per arc
        iono = arc["iono_true"].to_numpy()
        slopes.append(np.polyfit(iono, arc["cmc"].to_numpy(), 1)[0])
        spans.append(np.ptp(iono))
    print(f"\ncode-minus-carrier / ionosphere over {len(slopes)} arcs: median "
          f"{np.median(slopes):.3f}, spread {np.std(slopes):.3f}; ionosphere changed "
          f"{np.min(spans):.2f}-{np.max(spans):.2f} m")
    assert len(slopes) >= 5
    assert np.median(slopes) == pytest.approx(2.0, abs=0.1)


def test_geometry_free_phase_follows_the_true_differential_ionosphere(static_hour):
    """lambda1 Phi1 - lambda2 Phi2 = (gamma - 1) I1 + constant per arc (+ mm of noise and
    multipath): after each arc's mean is removed it follows (gamma - 1) I1 of the truth
    within millimetres while the ionosphere itself moves by decimetres."""
    raw, truth = static_hour
    raw = raw[(raw["lli"] & 2) == 0]  # half cycle unresolved: skipped, as RINEX 3.04 says
    pair = raw.pivot_table(index=["t", "sv"], columns="signal",
                           values=["carrier_phase", "frequency"]).dropna()
    gf = (C_M_S / pair[("frequency", "1C")] * pair[("carrier_phase", "1C")]
          - C_M_S / pair[("frequency", "2W")] * pair[("carrier_phase", "2W")]).rename("gf")
    arcs = truth[truth["signal"] == "1C"].set_index(["t", "sv"])[["iono_true"]]
    noise = truth.assign(e=truth["phase_noise"] + truth["carrier_multipath"]).pivot_table(
        index=["t", "sv"], columns="signal", values="e")
    arcs["noise"] = noise["1C"] - noise["2W"]
    arcs2 = truth[truth["signal"] == "2W"].set_index(["t", "sv"])["arc"].rename("arc2")
    arcs1 = truth[truth["signal"] == "1C"].set_index(["t", "sv"])["arc"].rename("arc1")
    rows = pd_join(gf, arcs, arcs1, arcs2)
    gamma = (1575.42 / 1227.60) ** 2
    rows["model"] = (gamma - 1.0) * rows["iono_true"]
    residual, unexplained, moved = [], [], []
    for _, arc in rows.groupby([rows.index.get_level_values("sv"), "arc1", "arc2"]):
        if len(arc) < 600:
            continue
        d = (arc["gf"] - arc["model"]).to_numpy()
        residual.append(d - d.mean())
        e = d - arc["noise"].to_numpy()
        unexplained.append(e - e.mean())
        moved.append(np.ptp(arc["model"]))
    residual = np.concatenate(residual)
    # what is left is the two carriers' noise and multipath, exactly
    assert np.max(np.abs(np.concatenate(unexplained))) < 1e-5
    print(f"\ngeometry-free phase minus (gamma-1) I: std {1e3 * np.std(residual):.2f} mm, "
          f"max {1e3 * np.max(np.abs(residual)):.1f} mm; differential ionosphere moved "
          f"{np.median(moved):.2f} m (median over arcs)")
    assert np.median(moved) > 0.1
    assert np.std(residual) < 0.005


def pd_join(*parts):
    import pandas as pd

    return pd.concat(parts, axis=1, join="inner")
