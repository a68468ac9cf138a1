"""A campaign on a Dask cluster (two worker processes on loopback): an estimator that never
returns is stopped at ``--time-limit`` and fails its own row, the other estimator's rows and
the other runs complete; a worker process killed mid-run fails that run (named by Dask's
``KilledWorker``) and the other sweep point's runs complete."""

from __future__ import annotations

import pandas as pd
import pytest

from simulator.cli import main
from tests.reliability.drives import estimator_scenario

PLUGINS = "tests.reliability.hostile_plugins"


@pytest.fixture(scope="module")
def cluster():
    """No retry of a run whose worker died (Dask's default runs it up to four times, each
    death a worker restart): the first death is the run's failure."""
    distributed = pytest.importorskip("distributed")
    import dask

    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), \
            distributed.LocalCluster(host="127.0.0.1", n_workers=2, threads_per_worker=1,
                                     processes=True, dashboard_address=None) as c:
        yield c


def test_the_time_limit_holds_on_dask_workers(cluster, tmp_path, capsys):
    scenario = estimator_scenario(tmp_path, 20, 25,
                                  f"[{{name: '{PLUGINS}:Holds', label: holds}}, "
                                  f"{{name: '{PLUGINS}:NeverReturns', label: never}}]")
    out = tmp_path / "mc"
    assert main(["campaign", str(scenario), "--runs", "2", "--scheduler",
                 cluster.scheduler_address, "--time-limit", "5", "-o", str(out)]) == 0
    runs = pd.read_parquet(out / "runs.parquet")
    holds, never = runs[runs["label"] == "holds"], runs[runs["label"] == "never"]
    assert (holds["status"] == "ok").all() and len(holds) == 2
    assert (never["status"] == "failed").all() and len(never) == 2
    for error in never["error"]:
        assert f"estimator '{PLUGINS}:NeverReturns'" in error
        assert "did not finish within the time limit of 5 s" in error
    assert "2 result(s) ok, 2 failed" in capsys.readouterr().out


@pytest.mark.slow  # about 10 s of CPU: two worker restarts
def test_a_worker_killed_mid_run_fails_that_run_only(cluster, tmp_path, capsys):
    scenario = estimator_scenario(tmp_path, 20, 25,
                                  f"[{{name: '{PLUGINS}:KillsItsWorker', label: kills}}]")
    out = tmp_path / "mc"
    assert main(["campaign", str(scenario), "--runs", "2", "--scheduler",
                 cluster.scheduler_address, "--sweep", "estimators.0.config.kill=false,true",
                 "-o", str(out)]) == 0
    runs = pd.read_parquet(out / "runs.parquet")
    spared, killed = (runs[runs["estimators.0.config.kill"] == v] for v in ("false", "true"))
    assert (spared["status"] == "ok").all() and len(spared) == 2
    assert (killed["status"] == "failed").all() and len(killed) == 2
    for error in killed["error"]:
        assert "KilledWorker" in error and "execute_run" in error
    assert "2 result(s) ok, 2 failed" in capsys.readouterr().out
