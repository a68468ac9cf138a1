"""Receiver error processes against their defining statistics: the two-state clock against the
Allan variance of its h-parameters (computed by allantools, an independent implementation) and the
tracking-noise formulas against their limiting forms (the canyon geometry: tests/environment)."""

from __future__ import annotations

import numpy as np
import pytest

from simulator.gnss.constants import CHIP_L1CA_M
from simulator.gnss.receiver import clock_process, dll_sigma_m, fll_sigma_hz


@pytest.mark.parametrize("h0, h_minus2", [(2e-19, 2e-20), (8e-20, 4e-23)])
def test_clock_allan_variance_matches_h_parameters(h0, h_minus2):
    """sigma_y^2(tau) = h0 / (2 tau) + (2 pi^2 / 3) h_-2 tau (the power-law noise relations
    for white and random-walk frequency noise, Riley, NIST SP 1065, 2008), checked with
    allantools' overlapping ADEV."""
    allantools = pytest.importorskip("allantools")
    rng = np.random.default_rng(11)
    bias, _ = clock_process(200_001, 1.0, h0, h_minus2, 0.0, 0.0, rng)
    taus = np.array([1.0, 10.0, 100.0, 1000.0])
    got_taus, adev, _, _ = allantools.oadev(bias, rate=1.0, data_type="phase", taus=taus)
    expected = np.sqrt(h0 / (2 * got_taus) + 2 * np.pi**2 / 3 * h_minus2 * got_taus)
    np.testing.assert_allclose(adev, expected, rtol=0.1)


def test_tracking_noise_limits():
    """At high C/N0 the DLL jitter tends to chip sqrt(B d / (2 C/N0)) and the FLL jitter to
    sqrt(4 B / C/N0) / (2 pi T) (Kaplan & Hegarty eqs. 8.51 and 8.37 without squaring loss)."""
    cn0_db = 60.0
    cn0 = 10 ** (cn0_db / 10)
    assert dll_sigma_m(cn0_db, 0.5, 0.5, 0.02) == pytest.approx(
        CHIP_L1CA_M * np.sqrt(0.5 * 0.5 / (2 * cn0)), rel=1e-3)
    assert fll_sigma_hz(cn0_db, 2.0, 0.02) == pytest.approx(
        np.sqrt(4 * 2.0 / cn0) / (2 * np.pi * 0.02), rel=1e-3)
    # weaker signals are noisier, and a 10 dB loss is more than sqrt(10) times the noise
    assert dll_sigma_m(30.0, 0.5, 0.5, 0.02) > np.sqrt(10) * dll_sigma_m(40.0, 0.5, 0.5, 0.02)
