"""``landnav reproduce`` through ``simulator.cli.main``: bad input (exit 2, one message, nothing
written), a failing run reported instead of a crash, and the quick run of every registered paper
end to end."""

from __future__ import annotations

import html
import json
import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from simulator.cli import main
from simulator.reproduce import runner, tan2008
from simulator.reproduce.papers import load_paper, paper_keys
from simulator.reproduce.runner import _execute, _Task, run_experiment
from tests.experiment_cache import in_this_process

pytestmark = pytest.mark.usefixtures("shared_experiments")  # each (experiment, seed) once

REPOSITORY = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("argv, message", [
    (["nosuchpaper"], "unknown paper 'nosuchpaper'"),
    (["--runs", "0"], "--runs: must be between 1"),
    (["--workers", "0"], "--workers: must be at least 1"),
    (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "not both"),
])
def test_bad_input_is_one_message_and_exit_2(tmp_path, capsys, argv, message):
    out = tmp_path / "out"
    assert main(["reproduce", *argv, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_an_existing_folder_is_not_replaced_without_force(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "mine.txt").write_text("keep")
    assert main(["reproduce", "tan2008", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "already exists; use --force" in err and "Traceback" not in err
    assert [p.name for p in out.iterdir()] == ["mine.txt"]
    assert not list(tmp_path.glob(".out.tmp*"))


def test_an_installation_without_the_shipped_scenarios_is_told_what_to_do(tmp_path, capsys,
                                                                           monkeypatch):
    from simulator.reproduce import paper

    monkeypatch.setattr(paper, "SCENARIO_DIR", tmp_path / "no-scenarios")
    out = tmp_path / "out"
    assert main(["reproduce", "tan2008", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "pip install -e" in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert not out.exists() and not list(tmp_path.glob(".out.tmp*"))
    # in a fresh interpreter, where the papers that read their scenarios when imported (Chan,
    # Karamat) are first imported by the command line itself
    code = ("import sys; from pathlib import Path; import simulator.reproduce.paper as p; "
            f"p.SCENARIO_DIR = Path({str(tmp_path / 'none')!r}); "
            "from simulator.cli import main; "
            f"sys.exit(main(['reproduce', 'chan', '-o', {str(out)!r}]))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, cwd=tmp_path,
                         env={**os.environ, "PYTHONPATH": str(REPOSITORY)})
    assert run.returncode == 2, run.stderr
    assert "pip install -e" in run.stderr and "Traceback" not in run.stderr
    assert not out.exists()


def test_a_failing_run_is_reported_with_its_error():
    figures, error, _ = _execute(_Task("tan2008", "outage", 1, ("no.such.key=1",)))
    assert figures is None
    assert "InputError" in error and "unknown key" in error


@pytest.mark.parametrize("runs", [1, pytest.param(3, marks=pytest.mark.slow)])
def test_quick_run_of_every_paper(tmp_path, capsys, monkeypatch, runs):
    """Every registered paper on its shortened drives end to end, one seed (``--quick``'s 3
    with --runslow; the claims themselves are asserted on seeds 1-3 by tests/estimators/). The
    report names each paper and every claim that is no variant with a figure and a word (each
    judge given only the experiments it declares), runs no experiment that only variants read,
    and the independent script recomputes every word from results.json. The tasks run in this
    process, where a seed the claim tests have computed is read, not computed again
    (tests/experiment_cache.py); the worker processes run in
    ``test_on_local_or_dask_workers_the_figures_are_those_of_an_in_process_run``."""
    monkeypatch.setattr(runner, "open_executor", in_this_process)
    out = tmp_path / "repro"
    assert main(["reproduce", "--quick", "--runs", str(runs), "--workers", "2", "-o",
                 str(out)]) == 0
    md = (out / "report.md").read_text()
    page = (out / "report.html").read_text()
    for key in paper_keys():
        paper = load_paper(key)
        quick = paper.quick()
        assert paper.title in md and html.escape(paper.title, quote=False) in page
        for experiment in quick.experiments:
            table = pd.read_parquet(out / "figures" / key / f"{experiment.key}.parquet")
            assert list(table.index) == list(range(1, runs + 1)), (key, experiment.key)
        left = {e.key for e in paper.experiments} - {e.key for e in quick.experiments}
        assert not [p for p in (out / "figures" / key).iterdir() if p.stem in left]
        for claim in paper.claims:
            if claim.variant_of or claim.full_only:  # --quick leaves these to the full run
                assert f"**{claim.key}**" not in md, claim.key
                continue
            if claim.untestable:
                continue
            (row,) = [line for line in md.splitlines() if f"**{claim.key}**" in line]
            assert "| no figure |" not in row and "could not be judged" not in row, row
            assert any(f"**{word}**:" in row for word in ("shown", "partly", "not shown")), row
    assert not (out / "failures.parquet").exists()
    assert "report:" in capsys.readouterr().out
    # every word follows from its per-seed values by the rule, recomputed independently
    run = subprocess.run([sys.executable, str(REPOSITORY / "tools" / "recompute_verdicts.py"),
                          str(out / "results.json")], capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    claims = json.loads((out / "results.json").read_text())["claims"]
    assert {c["kind"] for c in claims.values()} == {"paper", "check"}


def test_help_lists_the_papers(capsys):
    with pytest.raises(SystemExit):
        main(["reproduce", "--help"])
    text = capsys.readouterr().out
    for key in paper_keys():
        assert key in text
    assert "landnav reproduce --list" in text  # each paper's claims: tests/commands/test_help.py


@pytest.mark.parametrize("where", ["local", "dask"])
def test_on_local_or_dask_workers_the_figures_are_those_of_an_in_process_run(tmp_path, where):
    """Tan's outage (the smallest experiment), one seed, shortened drive, on a local worker
    process and on a loopback Dask cluster of one worker process: the figures stored equal
    those of ``run_experiment`` in this process (same scenario and seed, same numbers)."""
    out = tmp_path / where
    if where == "local":
        assert main(["reproduce", "tan2008", "--quick", "--runs", "1", "--workers", "1", "-o",
                     str(out)]) == 0
        assert "1 local worker process(es)" in (out / "report.md").read_text()
    else:
        distributed = pytest.importorskip("distributed")
        with distributed.LocalCluster(host="127.0.0.1", n_workers=1, threads_per_worker=1,
                                      processes=True, dashboard_address=None) as cluster:
            assert main(["reproduce", "tan2008", "--quick", "--runs", "1", "--scheduler",
                         cluster.scheduler_address, "-o", str(out)]) == 0
        assert "Dask scheduler" in (out / "report.md").read_text()
    stored = pd.read_parquet(out / "figures" / "tan2008" / "outage.parquet")
    expected = run_experiment(tan2008.OUTAGE, [1], tmp_path, quick=True)
    pd.testing.assert_frame_equal(stored, expected, check_exact=False, rtol=1e-12)
