"""The consistency table's tool (``benchmarks/consistency.py``): its drives validate, its rows
are the mean and the largest seed of each axis with the goal's verdict, and one seed of a short
drive runs end to end through the campaign, the table's figure equal to the one computed
directly from the filter's solution, and resumes without computing again."""

from __future__ import annotations

import textwrap

import numpy as np
import pandas as pd
import pytest

from benchmarks import consistency as tool
from simulator import pipeline
from simulator.scoring.consistency import normalised_errors

SHORT_DRIVE = textwrap.dedent("""\
    name: consistency-tool-check
    seed: 1
    start: {utc: 2023-09-12T06:30:00Z, lat: 35.1796, lon: 129.0756, alt: 60.0, heading: 30.0}
    trajectory:
      kind: segments
      segments:
        - stop: {duration: 5}
        - accelerate: {to_speed: 10.0, accel: 2.0}
        - straight: {length: 600}
        - turn: {angle: 90, radius: 50}
        - straight: {length: 200}
    sensors:
      imu: {preset: automotive, rate: 100}
      odometer: {preset: automotive}
      gnss: {preset: automotive, rate: 1, outputs: [fix]}
    estimators: [gnss_only]
    """)


@pytest.mark.parametrize("drive", tool.UNSEEN)
def test_the_unseen_drives_validate_and_give_their_filters(drive):
    overrides, runnable = tool.drive_overrides(tool.drive_path(drive), [], list(tool.FILTERS))
    assert "sensors.gnss.outputs=[fix,raw]" in overrides
    # every drive has an IMU, an odometer and a receiver: every listed filter runs on it
    assert runnable == list(tool.FILTERS)


def test_a_row_is_the_mean_and_the_largest_seed_with_the_goal():
    runs = pd.DataFrame({
        "seed": [1, 2, 3, 4], "label": ["f"] * 4, "status": ["ok", "ok", "ok", "failed"],
        "consistency.position.nse.n": [1.0, 2.0, 3.0, np.nan],   # mean 2, worst 3: in
        "consistency.position.nse.e": [0.1, 0.2, 0.3, np.nan],   # mean 0.2: out (low)
        "consistency.position.nse.d": [1.0, 1.0, 12.0, np.nan],  # mean 4.7: out; seed 12
        "consistency.yaw.nse.yaw": [0.5, 1.0, 1.5, np.nan],      # a 2-D block: in
    })
    values, failed = tool.axis_values(runs, "f")
    assert failed == 1 and set(values) == {"n", "e", "d", "yaw"}
    row = tool.table_row("drive", values, failed)
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[0] == "drive (3)"
    assert cells[1:4] == ["2 (3)", "0.2 (0.3)", "4.7 (12)"]
    assert cells[4:9] == ["", "", "", "", ""] and cells[9] == "1 (1.5)"
    assert cells[10] == "e, d; 1 run(s) failed"


def test_one_seed_of_a_short_drive_end_to_end(tmp_path, capsys):
    drive = tmp_path / "short.yaml"
    drive.write_text(SHORT_DRIVE)
    out = tmp_path / "out"
    argv = ["--seeds", "1", "--drives", str(drive), "--filters", "gnss_wls,dr2d_odo_ekf",
            "--workers", "1", "-o", str(out)]
    assert tool.main(argv) == 0
    table = (out / tool.OUTPUT).read_text()
    assert "### `gnss_wls`" in table and "### `dr2d_odo_ekf`" in table
    rows = {line.split("|")[1].strip(): line for line in table.splitlines()
            if line.startswith("| short")}
    assert list(rows) == ["short (1)"]
    # the table's gnss_wls north figure is the one computed from the solution itself
    scenario = pipeline.load_scenario(drive, ["sensors.gnss.outputs=[fix,raw]"], seed=1)
    dataset = pipeline.generate(scenario, tmp_path / "dataset")
    solution, _ = pipeline.estimate(dataset, "gnss_wls")
    direct = normalised_errors(dataset.read("truth"), solution)
    wls_row = table.split("### `gnss_wls`")[1].splitlines()[4]
    cells = [c.strip() for c in wls_row.strip("|").split("|")]
    assert float(cells[1]) == pytest.approx(direct["n"], rel=0.051)  # two digits printed
    assert float(cells[6]) == pytest.approx(direct["vd"], rel=0.051)  # two digits printed
    # the dr2d_odo_ekf row has the 2-D blocks: horizontal position and yaw, no height
    odo_row = table.split("### `dr2d_odo_ekf`")[1].splitlines()[4]
    odo = [c.strip() for c in odo_row.strip("|").split("|")]
    assert odo[1] and odo[2] and not odo[3] and odo[9]
    # the same command again resumes: nothing computed, the same table
    capsys.readouterr()
    assert tool.main(argv) == 0
    assert (out / tool.OUTPUT).read_text() == table
