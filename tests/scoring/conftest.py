"""Fixtures of the scoring tests: the shipped quickstart generated once per session."""

from __future__ import annotations

import pytest

from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import Dataset, open_dataset
from simulator.scenario import load_scenario
from tests.scoring_helpers import QUICKSTART


@pytest.fixture(scope="session")
def quickstart(tmp_path_factory) -> Dataset:
    """The shipped quickstart scenario's dataset (seed 1), generated once."""
    out = tmp_path_factory.mktemp("quickstart") / "dataset"
    return open_dataset(generate_dataset(load_scenario(QUICKSTART), out, show_progress=False))
