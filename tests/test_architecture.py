"""The package structure: every module imports on its own, and no module imports a layer above
its own (the layer order lives here, in ``LAYERS``).

The layers, lowest first, follow the data path: the core (Earth model, units, column names,
errors, the schema vocabulary, random processes) -> trajectory and environment -> GNSS -> sensors
-> faults -> scenario (assembles every part's schema and checks the whole) -> dataset ->
estimators (the plug-in API, the filter toolbox and the built-ins, which use the core only) ->
replay (the causal harness) -> scoring -> pipeline (the library entry points) -> campaigns ->
commands and the CLI. A module may import modules of its own layer and of the layers below.
The one exception: ``estimators.registry`` (estimator names to classes) may be imported from any
layer, so that a scenario's estimator names are checked where the scenario is.
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PACKAGES = ("simulator", "estimators")

# lowest first; a module belongs to the layer of its longest matching prefix
LAYERS: list[tuple[str, tuple[str, ...]]] = [
    ("core", ("simulator", "simulator.earth", "simulator.units", "simulator.columns",
              "simulator.errors", "simulator.schema", "simulator.tables", "simulator.timebase",
              "simulator.progress", "simulator.stochastic", "simulator.outputs",
              "simulator.geoid", "simulator.compilation", "simulator.threads",
              "simulator.display_units", "simulator.html_report", "simulator.datasheet")),
    ("trajectory", ("simulator.trajectory", "simulator.vehicle", "simulator.environment")),
    ("drive", ("simulator.drive",)),
    ("gnss", ("simulator.gnss",)),
    ("sensors", ("simulator.sensors",)),
    ("faults", ("simulator.faults",)),
    ("scenario", ("simulator.scenario",)),
    ("dataset", ("simulator.dataset", "simulator.recordings")),
    ("estimators", ("estimators",)),
    ("replay", ("simulator.replay", "simulator.isolated")),
    ("scoring", ("simulator.scoring",)),
    ("pipeline", ("simulator.pipeline", "simulator.comparison")),
    ("campaign", ("simulator.campaign",)),
    ("reproduce", ("simulator.reproduce",)),
    ("commands", ("simulator.commands", "simulator.cli")),
]
ANYWHERE = {"estimators.registry"}  # the estimator name registry
# estimators depend on the core only (and on each other): never on how datasets are made
ESTIMATOR_MAY_IMPORT = ("estimators",) + LAYERS[0][1]


def _modules() -> dict[str, Path]:
    found = {}
    for package in PACKAGES:
        for path in sorted((REPO / package).rglob("*.py")):
            parts = path.relative_to(REPO).with_suffix("").parts
            found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def _matches(module: str, prefix: str) -> bool:
    return module == prefix or module.startswith(prefix + ".")


def layer_of(module: str) -> int:
    """Index in ``LAYERS`` of the layer owning ``module`` (its longest matching prefix)."""
    best, length = None, -1
    for index, (_, prefixes) in enumerate(LAYERS):
        for prefix in prefixes:
            if _matches(module, prefix) and len(prefix) > length:
                best, length = index, len(prefix)
    if best is None:
        raise LookupError(f"{module} belongs to no layer: add it to LAYERS in {__file__}")
    return best


def imports_of(path: Path) -> list[tuple[int, str]]:
    """(line, module) of every import of our packages in a file, wherever it stands (in
    functions and ``TYPE_CHECKING`` blocks too); ``from package import module`` counts as an
    import of the module."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            for alias in node.names:
                name = f"{node.module}.{alias.name}"
                found.append((node.lineno, name if name in MODULES else node.module))
    return [(line, name) for line, name in found if name.split(".")[0] in PACKAGES]


MODULES = _modules()


def test_every_module_has_a_layer():
    for module in MODULES:
        layer_of(module)


def test_no_module_imports_a_layer_above_its_own():
    upward = []
    for module, path in MODULES.items():
        own = layer_of(module)
        for line, target in imports_of(path):
            if target in ANYWHERE:
                continue
            if layer_of(target) > own:
                upward.append(f"{path.relative_to(REPO)}:{line}: {module} ({LAYERS[own][0]}) "
                              f"imports {target} ({LAYERS[layer_of(target)][0]})")
            if _matches(module, "estimators") and not any(
                    _matches(target, prefix) for prefix in ESTIMATOR_MAY_IMPORT):
                upward.append(f"{path.relative_to(REPO)}:{line}: estimator module {module} "
                              f"imports {target} (estimators use the core only)")
    assert not upward, "\n".join(upward)


def test_the_layer_check_sees_an_upward_import(tmp_path):
    """The checker itself: a sensor importing the dataset layer, inside a function, is found."""
    bad = tmp_path / "bad.py"
    bad.write_text("def f():\n    from simulator.dataset.io import open_dataset\n")
    (line, target), = imports_of(bad)
    assert line == 2 and layer_of(target) > layer_of("simulator.sensors.imu")
    assert layer_of("simulator.sensors") < layer_of("simulator.faults") < layer_of("simulator.cli")


def _import_alone(module: str) -> tuple[str, int, str]:
    """Import ``module`` in a fresh interpreter (nothing imported before it but the standard
    library's start-up). Byte-code caches are written and read as on an ordinary installation
    (a sandbox's PYTHONDONTWRITEBYTECODE would make every interpreter recompile every module)."""
    env = {**{k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"},
           "PYTHONPATH": str(REPO)}
    done = subprocess.run([sys.executable, "-c", f"import {module}"], capture_output=True,
                          text=True, cwd=REPO, env=env)
    return module, done.returncode, done.stderr.strip().splitlines()[-1:]


@pytest.mark.parametrize("package", PACKAGES)
def test_every_module_imports_on_its_own(package):
    """One fresh interpreter per module, four per core at a time (much of an import waits on
    the disk and on the other processes of a busy machine): an import cycle, or a module that
    works only after another has been imported, fails here."""
    modules = [m for m in MODULES if _matches(m, package)]
    with ThreadPoolExecutor(max_workers=4 * (os.cpu_count() or 1)) as pool:
        failed = [f"{module}: {error}" for module, code, error in pool.map(_import_alone, modules)
                  if code != 0]
    assert not failed, "\n".join(failed)
