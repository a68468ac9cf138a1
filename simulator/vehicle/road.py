"""The road under each wheel: named features (speed bumps), a random roughness profile drawn from
the ISO 8608 spectrum of a road class, and the road's cross-slope (camber).

* Roughness: ISO 8608:2016 (Mechanical vibration - Road surface profiles - Reporting of measured
  data), eq. (5) with waviness w = 2: the displacement PSD Gd(n) = Gd(n0) (n / n0)^-2, n0 = 0.1
  cycle/m, over the standard's band 0.011-2.83 cycle/m (wavelengths 0.35-90 m). A track is the
  sum of cosines of amplitude sqrt(2 Gd(n_k) dn) and uniform random phase (the standard's
  Annex C method), summed by an inverse FFT on a 0.1 m grid. The left and right wheel tracks are
  independent draws (ISO 8608 does not relate them; real tracks are correlated at long
  wavelengths, which mainly excites heave rather than roll); a rear wheel runs in the front
  wheel's track, one wheelbase later. Content above the truth grid's Nyquist frequency at the
  driving speed (wavelengths under 2 v / rate) aliases: at 100 Hz, above 17 m/s.
* Speed bumps keep the shape of the segment (``segments``): z = H 64 u^3 (1 - u)^3, u = s / L.
* Camber: the right wheels stand ``camber`` x track lower than the left (a cross-slope falling to
  the right, as on a crowned road in right-hand traffic); it adds to any bank of the road.

Public names
------------
RoadSurface, draw_roughness.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

ISO_N0 = 0.1  # reference spatial frequency, cycle/m (ISO 8608)
ISO_BAND = (0.011, 2.83)  # the standard's spatial-frequency band, cycle/m
GRID_M = 0.1  # spacing of the drawn profile, m


def draw_roughness(length_m: float, gd_n0: float, rng: np.random.Generator,
                   tracks: int = 2) -> np.ndarray:
    """Road heights (m) of ``tracks`` independent tracks every ``GRID_M`` over ``length_m``.

    Parameters
    ----------
    length_m : float
        Length to cover, m (the profile is periodic beyond it).
    gd_n0 : float
        Gd(n0) of the road class, m^3 (``params.ROUGHNESS_CLASSES``).
    rng : numpy.random.Generator
        The road's own random stream.

    Returns
    -------
    array, shape (tracks, n)
    """
    n = 2 * int(np.ceil(length_m / GRID_M / 2)) + 2
    freq = np.fft.rfftfreq(n, GRID_M)  # cycle/m
    dn = freq[1]
    band = (freq >= ISO_BAND[0]) & (freq <= ISO_BAND[1])
    amplitude = np.zeros(len(freq))
    amplitude[band] = np.sqrt(2 * gd_n0 * (freq[band] / ISO_N0) ** -2 * dn)
    phase = rng.uniform(0.0, 2 * np.pi, (tracks, len(freq)))
    # numpy's irfft is (1/n) sum of X_k e^(i 2 pi k m / n) over both halves: X_k = n/2 A_k e^(i p)
    return np.fft.irfft(0.5 * n * amplitude * np.exp(1j * phase), n)


@dataclass
class RoadSurface:
    """Heights of the road under the wheels relative to the road's reference line.

    ``bumps`` holds (start s, length, height) of each speed bump (m); ``tracks`` the roughness of
    the left and right tracks on a grid starting at ``track_start`` (m of s), or None for a
    smooth road; ``camber`` the cross-slope (rise/run, + falling to the right).
    """

    bumps: list[tuple[float, float, float]]
    tracks: np.ndarray | None
    track_start: float
    camber: float

    def heights(self, s: np.ndarray, corner_x: np.ndarray,
                corner_y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Road height (m, up) under each corner (x_i forward, y_i right of the reference point,
        m) when the reference point is at distance s (non-decreasing) along the road, and the
        road's forward slope there (dz/ds: the linear interpolation's cell slope, the bump's
        derivative); each of shape (corners, len(s))."""
        z = np.empty((len(corner_x), len(s)))
        slope = np.zeros_like(z)
        grid_start, n_grid = self.track_start, 0 if self.tracks is None else self.tracks.shape[1]
        for i, (x, y) in enumerate(zip(corner_x, corner_y, strict=True)):
            if self.tracks is None:
                z[i] = 0.0
            else:  # the grid's index of s + x, and linear interpolation in the grid cell
                at = (s + (x - grid_start)) / GRID_M
                cell = np.clip(at.astype(np.intp), 0, n_grid - 2)
                track = self.tracks[int(y > 0)]
                left = track.take(cell)
                np.subtract(track.take(cell + 1), left, out=slope[i])
                z[i] = left + (at - cell) * slope[i]
                slope[i] /= GRID_M
            z[i] -= self.camber * y
            for start, length, height in self.bumps:  # a bump's rows are a run (s increases)
                rows = slice(*np.searchsorted(s, [start - x, start + length - x]))
                u = np.clip((s[rows] + x - start) / length, 0.0, 1.0)
                z[i, rows] += height * 64.0 * (u * (1 - u)) ** 3
                slope[i, rows] += height * 192.0 * (u * (1 - u)) ** 2 * (1 - 2 * u) / length
        return z, slope
