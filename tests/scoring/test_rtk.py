"""The rtk scores on hand-made epochs whose answers are counted by hand."""

from __future__ import annotations

import numpy as np

from simulator.scoring.rtk import rtk_scores


def test_counts_rates_and_times():
    t = np.arange(20.0)
    status = np.array([0, 1, 1, 2, 2, 2, 2, 2, 0, 0, 0, 1, 1, 1, 2, 2, 2, 2, 1, 2], float)
    error = np.full(20, 0.02)
    error[5] = 0.5                       # one wrong fix
    scores = rtk_scores(t, error, status, [(8.0, 11.0)])
    assert scores["epochs"] == 20 and scores["fixed_epochs"] == 10
    assert scores["fix_rate"] == 0.5
    assert scores["wrong_fix_rate"] == 0.1
    assert np.isclose(scores["fixed_rms"], np.sqrt((9 * 0.02**2 + 0.5**2) / 10))
    assert scores["time_to_first_fix"] == 3.0
    assert scores["refix_times"] == [3.0]  # GNSS back at 11 s, fixed again at 14 s


def test_no_fix_and_a_refix_that_never_comes():
    t = np.arange(10.0)
    status = np.array([1, 1, 1, 1, np.nan, 1, 1, 1, 1, 1])
    scores = rtk_scores(t, np.zeros(10), status, [(2.0, 4.0), (6.0, 7.0)])
    assert scores["epochs"] == 9 and scores["fix_rate"] == 0.0
    assert scores["fixed_rms"] is None and scores["time_to_first_fix"] is None
    assert scores["refix_times"] == [None, None]


def test_score_reads_fix_status_from_a_solution_file(quickstart, tmp_path):
    """A solution file with ``fix_status`` gets the ``rtk`` block from ``landnav score``: the
    truth itself, fixed on the first half, float after, with a 0.5 m jump on 3 fixed rows."""
    import json

    from simulator.cli import main

    truth = quickstart.read("truth").iloc[::100].reset_index(drop=True)
    solution = truth[["t", "lat", "lon", "alt", "vn", "ve", "vd", "roll", "pitch", "yaw"]].copy()
    half = len(solution) // 2
    solution["fix_status"] = np.where(np.arange(len(solution)) < half, 2, 1)
    solution.loc[[10, 11, 12], "alt"] += 0.5
    solution.to_csv(tmp_path / "rtk.csv", index=False)
    out = tmp_path / "s.json"
    assert main(["score", str(quickstart.path), "--solution", str(tmp_path / "rtk.csv"),
                 "--json", str(out)]) == 0
    rtk = json.loads(out.read_text())["rtk"]["rtk"]
    assert rtk["fixed_epochs"] == half and np.isclose(rtk["fix_rate"], half / len(solution))
    assert np.isclose(rtk["wrong_fix_rate"], 3 / half)
    assert rtk["time_to_first_fix"] == 0.0
    assert len(rtk["refix_times"]) == int((quickstart.read("events")["kind"]
                                           == "gnss_outage").sum())


def test_rtklib_quality_flag_reads_as_fix_status(tmp_path):
    """RTKLIB's Q (1 fixed, 2 float, 5 single) becomes fix_status 2, 1, 0 (SPEC section 8)."""
    from pathlib import Path

    from simulator.scoring.readers import read_solution_file

    source = Path(__file__).parent / "data" / "quickstart_llh_gpst.pos"
    lines = source.read_text().splitlines()
    data = [i for i, ln in enumerate(lines) if ln.strip() and not ln.startswith("%")]
    for i, q in zip(data[:3], ("1", "2", "5"), strict=True):
        fields = lines[i].split()
        fields[5] = q
        lines[i] = "  ".join(fields)
    path = tmp_path / "q.pos"
    path.write_text("\n".join(lines) + "\n")
    frame, _, _ = read_solution_file(path, (2312, 270018.0))
    assert frame["fix_status"].tolist()[:3] == [2, 1, 0]
    assert (frame["fix_status"].iloc[3:] == 0).all()
