"""The road builder's small polynomial helpers against numpy and scipy: the shift of a
polynomial's argument is numpy's composition bit for bit, and a piece's rise is the integral
of the sine of its grade."""

from __future__ import annotations

import numpy as np
from numpy.polynomial import Polynomial
from scipy.integrate import quad

from simulator.trajectory.segments import _rise_of, _shift


def test_shift_is_numpy_composition_bit_for_bit():
    rng = np.random.default_rng(7)
    for _ in range(3000):
        k = int(rng.integers(1, 7))
        coeffs = rng.normal(size=k) * 10.0 ** rng.integers(-12, 3, size=k)
        if rng.random() < 0.3:
            coeffs[rng.integers(k)] = 0.0  # zero coefficients, leading ones too
        offset = float(rng.normal() * 10.0 ** rng.integers(-3, 4))
        expected = Polynomial(coeffs[::-1])(Polynomial([offset, 1.0])).coef[::-1]
        got = _shift(coeffs, offset)
        assert got.shape == expected.shape
        assert np.array_equal(got.view(np.int64), expected.view(np.int64))


def test_rise_is_the_integral_of_the_sine_of_the_grade():
    grade = np.array([-2e-6, 3e-4, 0.004, 0.02])  # a cubic grade ramp, rad over s in m
    length = 40.0
    expected = quad(lambda s: np.sin(np.polyval(grade, s)), 0.0, length, epsabs=1e-13)[0]
    assert abs(_rise_of(length, grade) - expected) < 1e-9
    assert abs(_rise_of(length, np.array([0.1])) - np.sin(0.1) * length) < 1e-12
