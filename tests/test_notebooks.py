"""The worked examples in notebooks/ run from top to bottom (their cells assert what they show),
render at least one plot, and leave nothing behind in the repository."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.conftest import ci_and_slow

REPO = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((REPO / "notebooks").glob("*.ipynb"))


def _entries() -> set[Path]:
    """The repository's top-level entries and those of notebooks/ (where a notebook runs)."""
    return {*REPO.iterdir(), *(REPO / "notebooks").iterdir()}


# the default run's substitute for a line of a notebook (its Monte Carlo on fewer seeds: the
# same runs' first seeds, as run i has seed 1 + i); the notebook as written runs with --runslow
SHORTER = {"monte_carlo_sweep": ("seeds = 5  # runs per IMU grade\n",
                                 "seeds = 2  # runs per IMU grade (shortened for the tests)\n")}


CASES = [case for path in NOTEBOOKS for case in (
    ci_and_slow(f"{path.stem}-short", (path, True), (path, False), path.stem)
    if path.stem in SHORTER else [pytest.param(path, False, id=path.stem)])]


@pytest.mark.parametrize(("path", "shortened"), CASES)
def test_notebook_runs(path, shortened, monkeypatch):
    monkeypatch.setenv("MPLBACKEND", "Agg")
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    notebook = nbformat.read(path, as_version=4)
    if shortened:
        line, short = SHORTER[path.stem]
        (cell,) = [c for c in notebook.cells if line in c.source]
        cell.source = cell.source.replace(line, short)
    before = _entries()
    # a hang guard per cell (a first run compiles numba kernels: minutes on a loaded machine)
    client = nbclient.NotebookClient(notebook, timeout=1200, kernel_name="python3",
                                     resources={"metadata": {"path": str(REPO)}})
    client.execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code"
               for o in cell.get("outputs", [])]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    assert any("image/png" in o.get("data", {}) for o in outputs), "no plot was rendered"
    assert _entries() <= before, f"left behind: {sorted(map(str, _entries() - before))}"
