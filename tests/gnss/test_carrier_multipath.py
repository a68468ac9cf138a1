"""Carrier multipath of a moving antenna: the third-order PLL's closed-loop gain against the
loop simulated in the time domain (scipy.signal.lsim on the loop's integrators) and against its
noise bandwidth (the integral of |H|^2), and on a drive at 15 m/s the carrier multipath the
receiver records attenuated by the loop's mean gain at the reflections' fringe frequencies."""

from __future__ import annotations

import numpy as np
import pytest
from gnss_helpers import drive, receiver
from scipy import integrate, signal

from simulator.gnss.carrier import pll_response, reflection_path_rate_m_s
from simulator.gnss.constants import C_M_S

_A3, _B3, _BN_PER_OMEGA0 = 1.1, 2.4, 0.7845  # Kaplan & Hegarty 2017, Table 8.23


def _loop_state_space(bandwidth_hz: float):
    """The third-order PLL as Kaplan & Hegarty draw it (Fig. 8.27): the phase error e = input -
    NCO phase drives two integrators (w0^3 e and a w0^2 e + the first) and the NCO integrates
    b w0 e + the second; states (first integrator, second integrator, NCO phase)."""
    w0 = bandwidth_hz / _BN_PER_OMEGA0
    a = np.array([[0.0, 0.0, -w0**3], [1.0, 0.0, -_A3 * w0**2], [0.0, 1.0, -_B3 * w0]])
    b = np.array([[w0**3], [_A3 * w0**2], [_B3 * w0]])
    return a, b, np.array([[0.0, 0.0, 1.0]]), np.array([[0.0]])


@pytest.mark.parametrize("frequency_hz", [1.0, 3.0, 20.0, 75.0])
def test_pll_response_is_the_simulated_loops_gain(frequency_hz):
    """A sinusoidal phase input through the simulated 15 Hz loop: the NCO phase's amplitude
    once settled (the last two periods after 2 s; the loop settles within 0.5 s) is |H|."""
    t = np.arange(0.0, 2.0 + 2.0 / frequency_hz, 1.0 / (400.0 * max(frequency_hz, 1.0)))
    _, nco, _ = signal.lsim(_loop_state_space(15.0), np.sin(2 * np.pi * frequency_hz * t), t)
    settled = t >= 2.0
    amplitude = np.sqrt(2.0 * np.mean(nco[settled] ** 2))
    assert amplitude == pytest.approx(float(pll_response(frequency_hz, 15.0)), rel=5e-3)


@pytest.mark.parametrize("bandwidth_hz", [10.0, 15.0])
def test_pll_response_has_the_loops_noise_bandwidth(bandwidth_hz):
    """The integral of |H(f)|^2 over f >= 0 is the noise bandwidth B_n: 0.7845 w0 for the
    table's a = 1.1, b = 2.4 (its four digits: within 1e-4)."""
    noise_bandwidth, _ = integrate.quad(lambda f: pll_response(f, bandwidth_hz) ** 2, 0.0,
                                        np.inf, limit=500)
    assert noise_bandwidth == pytest.approx(bandwidth_hz, rel=1e-4)


def test_moving_antennas_carrier_multipath_is_attenuated_by_the_loop():
    """The geodetic preset (10 Hz loop, raw code, reflections 10 m long: relative amplitude
    under 0.04, so the carrier error is linear in it) on a 15 m/s straight, GPS L1: the
    reflection's in-phase part gives the code multipath m and its quadrature the carrier's
    (lambda / 2 pi d) m-sized error, so E[carrier^2] / E[m^2] (2 pi d / lambda)^2 is the loop's
    mean |H|^2 at the fringe frequencies. Predicted from the rows' geometry and velocity over
    reflectors of every orientation (a grid of 360 normals), against the measured ratio within
    four standard errors (the spread of the per-satellite ratios); 0.1-0.3 here, where a
    standing antenna keeps all of it."""
    truth = drive([{"accelerate": {"to_speed": 15.0, "accel": 3.0}},
                   {"straight": {"length": 9000}}], rate_hz=10.0)
    gnss = receiver(preset="geodetic", outputs=["raw"], carrier_phase=True,
                    systems=["gps"], signals={"gps": ["1C"]})
    table = gnss.generate(truth, np.random.default_rng(11))["truth_gnss"]
    rows = table.query("tracked == 1 and t >= 10").copy()
    wavelength = C_M_S / rows["frequency"].to_numpy()
    delay = 10.0  # the geodetic preset's multipath_delay
    scale = (2 * np.pi * delay / wavelength) ** 2
    rows["carrier2"] = rows["carrier_multipath"] ** 2 * scale
    rows["code2"] = rows["multipath"] ** 2
    # the loop's mean squared gain over reflector orientations, at each row (heading north at
    # 15 m/s once the 5 s of acceleration are over)
    v_ned = np.tile([15.0, 0.0, 0.0], (len(rows), 1))
    normals = np.linspace(0.0, np.pi, 360, endpoint=False)[:, None]
    az = np.radians(rows["azimuth"].to_numpy())[None, :]
    el = np.radians(rows["elevation"].to_numpy())[None, :]
    rate = reflection_path_rate_m_s(v_ned, az, el, normals + 0.0 * az)
    rows["gain2"] = np.mean(pll_response(rate / wavelength, 10.0) ** 2, axis=0) * rows["code2"]
    per_sat = rows.groupby("sv")[["carrier2", "code2", "gain2"]].sum()
    per_sat = per_sat[per_sat["code2"] > 0]
    measured = per_sat["carrier2"].sum() / per_sat["code2"].sum()
    predicted = per_sat["gain2"].sum() / per_sat["code2"].sum()
    ratios = per_sat["carrier2"] / per_sat["gain2"]
    standard_error = ratios.std() / np.sqrt(len(ratios)) * predicted
    print(f"\ncarrier multipath attenuation at 15 m/s: measured {measured:.3f}, predicted "
          f"{predicted:.3f} with a standard error of {standard_error:.3f} (over "
          f"{len(ratios)} satellites)")
    assert 0.05 < predicted < 0.5
    assert measured == pytest.approx(predicted, abs=4 * standard_error)
