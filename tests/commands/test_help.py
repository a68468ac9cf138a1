"""``landnav --help``, every ``landnav COMMAND --help`` and ``--version`` import no numerical
library: they answer in an interpreter's start-up time (a command imports what its work needs
inside its ``run``). Checked by what a fresh interpreter has imported, not by a clock."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from simulator import __version__
from simulator.cli import main
from simulator.commands import SUMMARIES

REPO = Path(__file__).resolve().parents[2]
HEAVY = ("matplotlib", "numba", "pandas", "scipy", "numpy", "pyarrow", "yaml", "dask")

PROBE = """
import contextlib, io, json, sys
from simulator.cli import main
argv = json.loads(sys.argv[1])
with contextlib.redirect_stdout(io.StringIO()):
    try:
        main(argv)
    except SystemExit as exc:
        code = exc.code
print(json.dumps({"code": code, "heavy": [m for m in json.loads(sys.argv[2]) if m in sys.modules]}))
"""


def _fresh(argv: list[str]) -> dict:
    done = subprocess.run([sys.executable, "-c", PROBE, json.dumps(argv), json.dumps(HEAVY)],
                          capture_output=True, text=True, cwd=REPO, timeout=600,
                          env={"PYTHONPATH": str(REPO), "PATH": "/usr/bin:/bin"})
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])


def test_help_of_every_command_imports_no_numerical_library():
    for argv in (["--help"], ["--version"], *([command, "--help"] for command in SUMMARIES)):
        seen = _fresh(argv)
        assert seen == {"code": 0, "heavy": []}, (argv, seen)


def test_version(capsys):
    try:
        main(["--version"])
    except SystemExit as exc:
        assert exc.code == 0
    assert capsys.readouterr().out.strip() == f"landnav {__version__}"


def test_reproduce_list_names_every_papers_claims(capsys):
    from simulator.reproduce.papers import load_paper, paper_keys

    try:
        main(["reproduce", "--list"])
    except SystemExit as exc:
        assert exc.code == 0
    text = capsys.readouterr().out
    for key in paper_keys():
        assert key in text and load_paper(key).claims[0].key in text
