"""Write ``simulator/data/egm96_15min.npz``, the EGM96 geoid grid of ``simulator.geoid``.

Source: the 5' EGM96 geoid grid bundled in the PyPI package ``egm96`` 0.3.0 (MIT; the grid is
GeographicLib's ``egm96-5`` dataset, EGM96 evaluated from its spherical-harmonic coefficients to
degree 360; EGM96 itself is a U.S. Government work in the public domain). That package needs
Python >= 3.12, so landnav does not depend on it: this tool reads its wheel once and keeps every
third node, the 15' x 15' grid of NGA's own ``WW15MGH`` file (721 x 1441 nodes, -90..90 deg
latitude, -180..180 deg longitude, both edges kept), in whole centimetres. The values are
stored as second differences (along latitude of the differences along longitude) in int16, which
compresses to about 0.7 MB; ``simulator.geoid`` undoes them with two cumulative sums.

Usage::

    pip download --no-deps --only-binary=:all: --python-version 3.12 -d /tmp/egm96 egm96==0.3.0
    PYTHONPATH=. python tools/make_egm96_grid.py /tmp/egm96/egm96-0.3.0-py3-none-any.whl
"""

from __future__ import annotations

import io
import sys
import zipfile
from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parents[1] / "simulator" / "data" / "egm96_15min.npz"
STEP = 3  # 15' / 5'


def main(wheel: str) -> None:
    with zipfile.ZipFile(wheel) as zf, np.load(io.BytesIO(zf.read("egm96/data/egm96-5.npz"))) as d:
        lat, lon = d["latitudes"], d["longitudes"]
        cm = np.cumsum(np.cumsum(d["undulation_d2"].astype(np.int32), axis=0), axis=1)
    assert lat[0] == -90.0 and lat[-1] == 90.0 and lon[0] == -180.0 and lon[-1] == 180.0
    grid_cm = cm[::STEP, ::STEP]
    d2 = np.diff(np.diff(grid_cm, axis=1, prepend=0), axis=0, prepend=0)
    assert np.abs(d2).max() < 2**15
    np.savez_compressed(OUT, undulation_cm_d2=d2.astype(np.int16),
                        first_lat_deg=np.float64(lat[0]), first_lon_deg=np.float64(lon[0]),
                        step_deg=np.float64(lon[STEP] - lon[0]))
    print(f"wrote {OUT} ({OUT.stat().st_size} bytes, {grid_cm.shape[0]} x {grid_cm.shape[1]})")


if __name__ == "__main__":
    main(sys.argv[1])
