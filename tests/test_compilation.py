"""numba kernels: every one of landnav's is cached on disk, and ``CompileWatch`` announces a
compilation once and times it, so that an estimator's runtime leaves it out."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest
from numba import njit

from simulator.dataset.io import open_dataset
from simulator.replay import run_estimator
from tests.recording import Recorder
from tests.synthetic import write_synthetic

REPO = Path(__file__).resolve().parents[1]

KERNEL = '''
from numba import njit


@njit(cache=True)
def twice(x):
    return 2.0 * x
'''


def _jit_decorators(path: Path) -> list[tuple[int, ast.expr]]:
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.FunctionDef):
            for deco in node.decorator_list:
                func = deco.func if isinstance(deco, ast.Call) else deco
                name = getattr(func, "id", getattr(func, "attr", ""))
                if name in ("njit", "jit"):
                    found.append((node.lineno, deco))
    return found


def test_every_numba_kernel_is_cached_on_disk():
    kernels = [(path, line, deco) for folder in ("estimators", "simulator")
               for path in sorted((REPO / folder).rglob("*.py"))
               for line, deco in _jit_decorators(path)]
    assert kernels  # the INS kernels at least
    uncached = [f"{path.relative_to(REPO)}:{line}" for path, line, deco in kernels
                if not (isinstance(deco, ast.Call) and any(
                    k.arg == "cache" and getattr(k.value, "value", None) is True
                    for k in deco.keywords))]
    assert not uncached, f"numba kernels without cache=True: {uncached}"


def _first_call(module_dir: Path) -> subprocess.CompletedProcess:
    code = ("import sys\nfrom simulator.compilation import CompileWatch\nimport kernel\n"
            "with CompileWatch('twice') as watch:\n    assert kernel.twice(1.5) == 3.0\n"
            "print(watch.seconds)\n")
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300, cwd=module_dir,
                          env={"PYTHONPATH": f"{module_dir}:{REPO}", "PATH": "/usr/bin:/bin"})


def test_first_compile_is_announced_and_the_next_process_loads_the_cache(tmp_path):
    (tmp_path / "kernel.py").write_text(KERNEL)
    first, second = _first_call(tmp_path), _first_call(tmp_path)
    announcement = "compiling numba kernels for twice (first run only)"
    assert first.returncode == 0, first.stderr
    assert first.stderr.count(announcement) == 1
    assert float(first.stdout) > 0
    assert list((tmp_path / "__pycache__").glob("kernel.twice-*.nbi"))  # numba's cache index
    assert second.returncode == 0, second.stderr
    assert announcement not in second.stderr
    assert float(second.stdout) == 0.0


@njit  # uncached on purpose: compiled at its first call in a process, inside the replay
def _unchanged(x):
    return x + 0.0


class Compiling(Recorder):
    """The recorder, its solution passed through a numba kernel compiled on first use."""

    def solution(self, t):
        row = super().solution(t)
        return [_unchanged(row[0]), *row[1:]]


def test_the_replay_leaves_the_compilation_out_of_the_runtime(tmp_path, capsys):
    dataset = open_dataset(write_synthetic(tmp_path / "syn", streams=("imu",)))
    _, first = run_estimator(dataset, "tests.test_compilation:Compiling", show_progress=False)
    _, again = run_estimator(dataset, "tests.test_compilation:Compiling", show_progress=False)
    err = capsys.readouterr().err
    assert err.count("compiling numba kernels for tests.test_compilation:Compiling "
                     "(first run only)") == 1
    assert first["compile_s"] > 0 and again["compile_s"] == 0.0
    for info in (first, again):  # runtime and real-time factor describe the same timed loop
        assert info["runtime_s"] > 0
        assert info["realtime_factor"] * info["runtime_s"] == pytest.approx(
            dataset.manifest["duration"], rel=1e-2)
